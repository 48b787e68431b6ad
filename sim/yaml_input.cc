#include "sim/yaml_input.h"

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

}  // namespace sim
