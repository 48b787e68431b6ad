#include "sim/yaml_input.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <system_error>

namespace sim {
namespace {

namespace fs = std::filesystem;

// Nodes visited by the duplicate check at most: aliases share nodes, so a small document can
// reach many ("billion laughs"); past this the document is refused rather than walked.
constexpr long kMaxYamlNodesVisited = 1000000;

std::string Join(const std::string& prefix, const std::string& key) {
  return prefix.empty() ? key : prefix + "." + key;
}

class DuplicateKeyCheck {
 public:
  explicit DuplicateKeyCheck(const std::string& source) : source_(source) {}

  bool Visit(const YAML::Node& node, const std::string& path, std::string* error) {
    if (++visited_ > kMaxYamlNodesVisited) {
      *error = source_ + ": more than " + std::to_string(kMaxYamlNodesVisited) +
               " YAML nodes (aliases nested too deep?)";
      return false;
    }
    if (node.IsMap()) {
      std::map<std::string, int> first_line;  // key -> line of its first occurrence (1-based)
      for (const auto& kv : node) {
        if (!kv.first.IsScalar()) continue;  // complex keys: the readers refuse them by name
        const std::string key = kv.first.Scalar();
        const int line = kv.first.Mark().line + 1;
        const auto [it, inserted] = first_line.emplace(key, line);
        if (!inserted) {
          *error = source_ + ":" + std::to_string(line) + ": key '" + Join(path, key) +
                   "': duplicate (first at line " + std::to_string(it->second) + ")";
          return false;
        }
        if (!Visit(kv.second, Join(path, key), error)) return false;
      }
    } else if (node.IsSequence()) {
      for (size_t i = 0; i < node.size(); ++i)
        if (!Visit(node[i], path + "[" + std::to_string(i) + "]", error)) return false;
    }
    return true;
  }

 private:
  const std::string& source_;
  long visited_ = 0;
};

}  // namespace

bool ReadInputFile(const std::string& path, const std::string& what, std::string* text,
                   std::string* error) {
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (!fs::exists(st)) {
    *error = path + ": no such file (expected a " + what + ")";
    return false;
  }
  if (fs::is_directory(st)) {
    *error = path + ": is a folder, expected a " + what;
    return false;
  }
  if (!fs::is_regular_file(st)) {
    *error = path + ": not a regular file, expected a " + what;
    return false;
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    *error = path + ": cannot open the " + what + " for reading";
    return false;
  }
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) {
    *error = path + ": read error in the " + what;
    return false;
  }
  *text = buffer.str();
  return true;
}

bool CheckNoDuplicateKeys(const YAML::Node& root, const std::string& source_name,
                          std::string* error) {
  DuplicateKeyCheck check(source_name);
  return check.Visit(root, "", error);
}

bool LoadYamlDocument(const std::string& text, const std::string& source_name, YAML::Node* root,
                      std::string* error) {
  try {
    *root = YAML::Load(text);
  } catch (const YAML::Exception& ex) {
    *error = source_name + ":" + std::to_string(ex.mark.line + 1) + ": malformed YAML: " + ex.msg;
    return false;
  }
  return CheckNoDuplicateKeys(*root, source_name, error);
}

// ---------------------------------------------------------------------------------------------
// YamlReader

namespace {

std::string NumberText(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

std::string ListText(const std::vector<std::string>& names) {
  std::string list;
  for (const auto& a : names) list += (list.empty() ? "" : ", ") + a;
  return list;
}

}  // namespace

YamlReader::YamlReader(std::string source_name) : source_(std::move(source_name)) {}

bool YamlReader::Parse(const std::string& text) {
  if (!ok()) return false;
  std::string why;
  if (!LoadYamlDocument(text, source_, &root_, &why)) return SetError(why);
  return true;
}

bool YamlReader::ParseFile(const std::string& path, const std::string& what) {
  if (!ok()) return false;
  std::string text, why;
  if (!ReadInputFile(path, what, &text, &why)) return SetError(why);
  return Parse(text);
}

bool YamlReader::Report(std::string* error) const {
  if (!ok() && error != nullptr) *error = error_;
  return ok();
}

std::string YamlReader::Where(const YAML::Node& node) const {
  if (node.IsDefined() && node.Mark().line >= 0)
    return source_ + ":" + std::to_string(node.Mark().line + 1);
  return source_;
}

bool YamlReader::Fail(const YAML::Node& at, const std::string& key, const std::string& what) {
  if (ok()) error_ = Where(at) + (key.empty() ? "" : ": key '" + key + "'") + ": " + what;
  return false;
}

bool YamlReader::SetError(const std::string& message) {
  if (ok()) error_ = message.empty() ? source_ + ": error" : message;
  return false;
}

std::string YamlReader::Join(const std::string& prefix, const std::string& key) {
  return prefix.empty() ? key : prefix + "." + key;
}

std::string YamlReader::Item(const std::string& key, size_t index) {
  return key + "[" + std::to_string(index) + "]";
}

bool YamlReader::Has(const YAML::Node& map, const std::string& key) {
  return map.IsMap() && map[key].IsDefined();
}

bool YamlReader::ExpectMap(const YAML::Node& node, const std::string& key,
                           const std::string& what) {
  if (!ok()) return false;
  if (node.IsMap()) return true;
  return Fail(node, key, "expected " + (what.empty() ? std::string("a mapping") : what));
}

bool YamlReader::CheckKeys(const YAML::Node& map, const std::string& prefix,
                           const std::vector<std::string>& allowed) {
  if (!ExpectMap(map, prefix)) return false;
  for (const auto& kv : map) {
    const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : "";
    bool known = false;
    for (const auto& a : allowed) known = known || a == key;
    if (!known)
      return Fail(kv.first, Join(prefix, key),
                  "unknown key (expected one of: " + ListText(allowed) + ")");
  }
  return true;
}

bool YamlReader::Require(const YAML::Node& map, const std::string& prefix, const std::string& key,
                         const std::string& what) {
  if (!ok()) return false;
  if (Has(map, key)) return true;
  return Fail(map, Join(prefix, key), "required: " + what);
}

bool YamlReader::Check(bool condition, const YAML::Node& map, const std::string& prefix,
                       const std::string& key, const std::string& what) {
  if (!ok()) return false;
  if (condition) return true;
  return Fail(Has(map, key) ? map[key] : map, Join(prefix, key), what);
}

bool YamlReader::Present(const YAML::Node& value, const std::string& key) {
  // A missing key of a const mapping is an invalid node, on which type queries throw.
  if (value.IsDefined()) return true;
  return Fail(value, key, "required: a value");
}

bool YamlReader::ReadString(const YAML::Node& value, const std::string& key, std::string* out,
                            bool allow_empty) {
  if (!ok()) return false;
  if (!Present(value, key)) return false;
  if (!value.IsScalar() || (!allow_empty && value.Scalar().empty()))
    return Fail(value, key, allow_empty ? "expected a string" : "expected a non-empty string");
  *out = value.Scalar();
  return true;
}

bool YamlReader::ReadDouble(const YAML::Node& value, const std::string& key, double* out) {
  if (!ok()) return false;
  if (!Present(value, key)) return false;
  if (!value.IsScalar()) return Fail(value, key, "expected a number");
  double v = 0.0;
  try {
    v = value.as<double>();
  } catch (const YAML::Exception&) {
    return Fail(value, key, "expected a number, got '" + value.Scalar() + "'");
  }
  if (!std::isfinite(v)) return Fail(value, key, "expected a finite number, got " + value.Scalar());
  *out = v;
  return true;
}

bool YamlReader::ReadDoubleIn(const YAML::Node& value, const std::string& key, double lo, double hi,
                              double* out) {
  double v = 0.0;
  if (!ReadDouble(value, key, &v)) return false;
  if (!(v >= lo && v <= hi))
    return Fail(value, key,
                "expected a finite value in [" + NumberText(lo) + ", " + NumberText(hi) +
                    "], got " + value.Scalar());
  *out = v;
  return true;
}

bool YamlReader::ReadInt(const YAML::Node& value, const std::string& key, long long lo,
                         long long hi, long long* out) {
  if (!ok()) return false;
  if (!Present(value, key)) return false;
  long long v = 0;
  try {
    if (!value.IsScalar()) throw YAML::Exception(value.Mark(), "");
    v = value.as<long long>();
  } catch (const YAML::Exception&) {
    return Fail(value, key,
                "expected an integer, got '" +
                    (value.IsScalar() ? value.Scalar()
                                      : "a " + std::string(value.IsMap()        ? "mapping"
                                                           : value.IsSequence() ? "list"
                                                                                : "null")) +
                    "'");
  }
  if (v < lo || v > hi) {
    const bool unbounded =
        hi == std::numeric_limits<long long>::max() || hi == std::numeric_limits<int>::max();
    const std::string range = unbounded
                                  ? ">= " + std::to_string(lo)
                                  : "in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
    return Fail(value, key, "expected an integer " + range + ", got " + value.Scalar());
  }
  *out = v;
  return true;
}

bool YamlReader::ReadWholeNumber(const YAML::Node& value, const std::string& key, long long lo,
                                 long long hi, long long* out) {
  if (!ok()) return false;
  if (!Present(value, key)) return false;
  double d = 0.0;
  bool number = value.IsScalar();
  if (number) {
    try {
      d = value.as<double>();
    } catch (const YAML::Exception&) {
      number = false;
    }
  }
  if (!number || !std::isfinite(d) || d != std::round(d) || d < static_cast<double>(lo) ||
      d > static_cast<double>(hi)) {
    std::string text = value.IsScalar() ? value.Scalar() : "a non-scalar";
    if (value.IsSequence() || value.IsMap()) {
      YAML::Emitter flow;
      flow << YAML::Flow << value;
      text = flow.c_str();
    }
    return Fail(value, key,
                "expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                    "], got '" + text + "'");
  }
  *out = static_cast<long long>(d);
  return true;
}

bool YamlReader::ReadUint64(const YAML::Node& value, const std::string& key, uint64_t* out) {
  if (!ok()) return false;
  if (!Present(value, key)) return false;
  try {
    if (!value.IsScalar() || value.Scalar().empty() || value.Scalar()[0] == '-')
      throw YAML::Exception(value.Mark(), "");
    *out = value.as<uint64_t>();
  } catch (const YAML::Exception&) {
    return Fail(value, key,
                "expected a non-negative integer, got '" +
                    (value.IsScalar() ? value.Scalar() : std::string("a non-scalar")) + "'");
  }
  return true;
}

bool YamlReader::ReadBool(const YAML::Node& value, const std::string& key, bool* out) {
  if (!ok()) return false;
  if (!Present(value, key)) return false;
  try {
    if (!value.IsScalar()) throw YAML::Exception(value.Mark(), "");
    *out = value.as<bool>();
  } catch (const YAML::Exception&) {
    return Fail(value, key,
                "expected true or false, got '" +
                    (value.IsScalar() ? value.Scalar() : std::string("a non-scalar")) + "'");
  }
  return true;
}

bool YamlReader::ReadName(const YAML::Node& value, const std::string& key,
                          const std::vector<std::string>& names, size_t* index) {
  if (!ok()) return false;
  if (!Present(value, key)) return false;
  if (value.IsScalar()) {
    for (size_t i = 0; i < names.size(); ++i) {
      if (value.Scalar() == names[i]) {
        *index = i;
        return true;
      }
    }
  }
  return Fail(value, key,
              "expected one of " + ListText(names) + "; got '" +
                  (value.IsScalar() ? value.Scalar() : std::string("a non-scalar")) + "'");
}

bool YamlReader::ReadNumbers(const YAML::Node& value, const std::string& key, size_t count,
                             std::vector<double>* out, const std::string& what) {
  if (!ok()) return false;
  if (!Present(value, key)) return false;
  const std::string expected =
      what.empty()
          ? "expected a list of " + (count > 0 ? std::to_string(count) : "any") + " numbers"
          : "expected " + what;
  if (!value.IsSequence() || (count > 0 && value.size() != count))
    return Fail(value, key, expected);
  std::vector<double> v;
  for (size_t i = 0; i < value.size(); ++i) {
    double d = 0.0;
    if (!ReadDouble(value[i], Item(key, i), &d)) return false;
    v.push_back(d);
  }
  *out = v;
  return true;
}

bool YamlReader::ReadPairs(const YAML::Node& value, const std::string& key,
                           std::vector<std::pair<double, double>>* out, const std::string& what,
                           const std::string& item_what) {
  if (!ok()) return false;
  if (!Present(value, key)) return false;
  if (!value.IsSequence())
    return Fail(value, key, "expected " + (what.empty() ? std::string("a list of pairs") : what));
  std::vector<std::pair<double, double>> v;
  for (size_t i = 0; i < value.size(); ++i) {
    const YAML::Node item = value[i];
    const std::string item_key = Item(key, i);
    if (!item.IsSequence() || item.size() != 2)
      return Fail(item, item_key,
                  "expected " + (item_what.empty() ? std::string("a pair [a, b]") : item_what));
    double p[2];
    for (int k = 0; k < 2; ++k) {
      try {
        if (!item[k].IsScalar()) throw YAML::Exception(item.Mark(), "");
        p[k] = item[k].as<double>();
      } catch (const YAML::Exception&) {
        return Fail(item, item_key, "expected numbers, got '" + item[k].Scalar() + "'");
      }
      if (!std::isfinite(p[k]))
        return Fail(item, item_key, "expected finite numbers, got " + item[k].Scalar());
    }
    v.emplace_back(p[0], p[1]);
  }
  *out = v;
  return true;
}

bool YamlReader::String(const YAML::Node& map, const std::string& prefix, const std::string& key,
                        std::string* out, bool allow_empty) {
  if (!ok()) return false;
  if (!Has(map, key)) return true;
  return ReadString(map[key], Join(prefix, key), out, allow_empty);
}

bool YamlReader::Double(const YAML::Node& map, const std::string& prefix, const std::string& key,
                        double* out) {
  if (!ok()) return false;
  if (!Has(map, key)) return true;
  return ReadDouble(map[key], Join(prefix, key), out);
}

bool YamlReader::Uint64(const YAML::Node& map, const std::string& prefix, const std::string& key,
                        uint64_t* out) {
  if (!ok()) return false;
  if (!Has(map, key)) return true;
  return ReadUint64(map[key], Join(prefix, key), out);
}

bool YamlReader::Bool(const YAML::Node& map, const std::string& prefix, const std::string& key,
                      bool* out) {
  if (!ok()) return false;
  if (!Has(map, key)) return true;
  return ReadBool(map[key], Join(prefix, key), out);
}

}  // namespace sim
