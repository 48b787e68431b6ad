// Reading input files the strict way: a whole text file (a folder, a missing or unreadable path
// is an error that names it), a YAML document whose mappings have no duplicate keys, and
// YamlReader, the one strict reader over such a document. Every YAML reader of vobench is built
// on YamlReader: scenarios (sim/scenario.cc), VO configs (harness/vo_config.cc), suites
// (harness/suite/spec.cc), tune files (harness/tune.cc) and the EuRoC sensor.yaml
// (harness/dataset/euroc.cc). It lives in sim/ because harness/ depends on sim/.
#pragma once

#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace sim {

// Reads the file at `path` into *text. Fails, naming the path, when it does not exist, is a
// folder (or anything but a regular file), cannot be opened or cannot be read to the end.
// `what` names the expected content in the messages ("scenario file", "VO config file").
bool ReadInputFile(const std::string& path, const std::string& what, std::string* text,
                   std::string* error);

// Parses `text` as one YAML document and refuses a mapping, at any depth, that holds the same
// key twice (yaml-cpp keeps both entries and lookups see the first, so the second would be
// ignored silently). Messages:
//   "SOURCE:LINE: malformed YAML: ..."
//   "SOURCE:LINE: key 'a.b': duplicate (first at line N)"   (LINE: the second occurrence)
// Keys in the message are dotted from the top, with "[i]" for list items ("scenarios[1].name").
bool LoadYamlDocument(const std::string& text, const std::string& source_name, YAML::Node* root,
                      std::string* error);

// The duplicate-key check of LoadYamlDocument on an already-parsed node.
bool CheckNoDuplicateKeys(const YAML::Node& root, const std::string& source_name,
                          std::string* error);

// The one strict reader of vobench's YAML inputs. Every message has one format:
//   "SOURCE:LINE: key 'a.b': WHAT"
// with the key dotted from the top and "[i]" for list items ("scenarios[1].set",
// "path[0]"), LINE the line of the offending node (1-based; left out where there is none).
// The first error is kept; after it every call does nothing and returns false, so a reader can
// run a series of getters and look at ok() once.
//
// Getters come in two forms. ReadX(value, key, out) reads a value node whose full key is `key`.
// X(map, prefix, key, out) reads map[key] with the full key Join(prefix, key); an absent key (or
// a `map` that is no mapping, which CheckKeys refuses) leaves *out as it is and returns true, so
// defaults stay where they are; use Has() / Require() for keys that must be there.
// On failure *out is left as it is.
class YamlReader {
 public:
  // `source_name` starts every message (a path, or "(VO overrides)" for generated text).
  explicit YamlReader(std::string source_name);

  // Parses `text` with LoadYamlDocument (duplicate keys refused) into root().
  bool Parse(const std::string& text);
  // ReadInputFile(path, what) + Parse; the source name stays the one given to the constructor.
  bool ParseFile(const std::string& path, const std::string& what);
  const YAML::Node& root() const { return root_; }
  const std::string& source() const { return source_; }

  bool ok() const { return error_.empty(); }
  const std::string& error() const { return error_; }
  // Copies the error (if any) to *error; returns ok().
  bool Report(std::string* error) const;

  // "SOURCE:LINE" at `node`, or "SOURCE" where the node has no line.
  std::string Where(const YAML::Node& node) const;
  // Records "Where(at): key 'KEY': WHAT" (no key part when `key` is empty). Returns false.
  bool Fail(const YAML::Node& at, const std::string& key, const std::string& what);
  // Records a message that already names its place (from a nested reader). Returns false.
  bool SetError(const std::string& message);

  static std::string Join(const std::string& prefix, const std::string& key);
  static std::string Item(const std::string& key, size_t index);  // "key[index]"
  // Whether `map` is a mapping that holds `key`.
  static bool Has(const YAML::Node& map, const std::string& key);

  // --- mappings ---------------------------------------------------------------------------
  // `node` must be a mapping: else "expected a mapping" (or "expected WHAT" when given).
  bool ExpectMap(const YAML::Node& node, const std::string& key, const std::string& what = "");
  // `map` must be a mapping whose keys are all in `allowed`; an unknown key fails at its line
  // with "unknown key (expected one of: a, b, c)" (the allowed keys in the order given).
  bool CheckKeys(const YAML::Node& map, const std::string& prefix,
                 const std::vector<std::string>& allowed);
  // map[key] must be there: else, at the map, "key 'KEY': required: WHAT".
  bool Require(const YAML::Node& map, const std::string& prefix, const std::string& key,
               const std::string& what);

  // A check on a value already read: when `condition` is false, fails with WHAT at map[key]
  // (at the map when the key is absent).
  bool Check(bool condition, const YAML::Node& map, const std::string& prefix,
             const std::string& key, const std::string& what);

  // --- values (value node + its full key) ------------------------------------------------
  // A scalar; "expected a string" / "expected a non-empty string".
  bool ReadString(const YAML::Node& value, const std::string& key, std::string* out,
                  bool allow_empty = true);
  // A finite number: "expected a number[, got 'X']", "expected a finite number, got X".
  bool ReadDouble(const YAML::Node& value, const std::string& key, double* out);
  // A finite number in [lo, hi]: "expected a finite value in [lo, hi], got X" out of range.
  bool ReadDoubleIn(const YAML::Node& value, const std::string& key, double lo, double hi,
                    double* out);
  // An integer (digits, no decimal point) in [lo, hi]: "expected an integer, got 'X'", or
  // when out of range "expected an integer in [lo, hi], got X" (">= lo" when hi is the largest
  // int or long long: no upper bound but the type's).
  bool ReadInt(const YAML::Node& value, const std::string& key, long long lo, long long hi,
               long long* out);
  template <typename T>
  bool ReadInt(const YAML::Node& value, const std::string& key, T lo, T hi, T* out) {
    long long v = 0;
    if (!ReadInt(value, key, static_cast<long long>(lo), static_cast<long long>(hi), &v))
      return false;
    *out = static_cast<T>(v);
    return true;
  }
  // A number with a whole value in [lo, hi], written as any number may be ("3", "3.0", "1e3";
  // tune files take their counts so): "expected an integer in [lo, hi], got 'X'".
  bool ReadWholeNumber(const YAML::Node& value, const std::string& key, long long lo, long long hi,
                       long long* out);
  template <typename T>
  bool ReadWholeNumber(const YAML::Node& value, const std::string& key, T lo, T hi, T* out) {
    long long v = 0;
    if (!ReadWholeNumber(value, key, static_cast<long long>(lo), static_cast<long long>(hi), &v))
      return false;
    *out = static_cast<T>(v);
    return true;
  }
  // A non-negative integer up to 2^64 - 1: "expected a non-negative integer, got 'X'".
  bool ReadUint64(const YAML::Node& value, const std::string& key, uint64_t* out);
  // true / false (also YAML's yes/no/on/off): "expected true or false, got 'X'".
  bool ReadBool(const YAML::Node& value, const std::string& key, bool* out);
  // One of the names of `table`: "expected one of a, b; got 'X'".
  template <typename E>
  bool ReadEnum(const YAML::Node& value, const std::string& key,
                const std::vector<std::pair<std::string, E>>& table, E* out) {
    std::vector<std::string> names;
    for (const auto& [name, v] : table) names.push_back(name);
    size_t index = 0;
    if (!ReadName(value, key, names, &index)) return false;
    *out = table[index].second;
    return true;
  }
  // A list of `count` finite numbers (any number of them when count is 0):
  // "expected a list of N numbers" (or "expected WHAT" when given) at the list, a bad item as
  // ReadDouble does under the key "key[i]".
  bool ReadNumbers(const YAML::Node& value, const std::string& key, size_t count,
                   std::vector<double>* out, const std::string& what = "");
  // A list of pairs [a, b] of finite numbers, "[i]" in the key of a bad item:
  // "expected a list of pairs" (or WHAT), "key 'k[i]': expected a pair [a, b]" (or ITEM_WHAT).
  bool ReadPairs(const YAML::Node& value, const std::string& key,
                 std::vector<std::pair<double, double>>* out, const std::string& what = "",
                 const std::string& item_what = "");

  // --- the same on optional keys of a mapping: map[key] when present ---------------------
  bool String(const YAML::Node& map, const std::string& prefix, const std::string& key,
              std::string* out, bool allow_empty = true);
  bool Double(const YAML::Node& map, const std::string& prefix, const std::string& key,
              double* out);
  template <typename T>
  bool Int(const YAML::Node& map, const std::string& prefix, const std::string& key, T lo, T hi,
           T* out) {
    if (!ok()) return false;
    if (!Has(map, key)) return true;
    return ReadInt(map[key], Join(prefix, key), lo, hi, out);
  }
  bool Uint64(const YAML::Node& map, const std::string& prefix, const std::string& key,
              uint64_t* out);
  bool Bool(const YAML::Node& map, const std::string& prefix, const std::string& key, bool* out);
  template <typename E>
  bool Enum(const YAML::Node& map, const std::string& prefix, const std::string& key,
            const std::vector<std::pair<std::string, E>>& table, E* out) {
    if (!ok()) return false;
    if (!Has(map, key)) return true;
    return ReadEnum(map[key], Join(prefix, key), table, out);
  }

 private:
  // false (and an error) when `value` is undefined: a key that is not there.
  bool Present(const YAML::Node& value, const std::string& key);
  bool ReadName(const YAML::Node& value, const std::string& key,
                const std::vector<std::string>& names, size_t* index);

  std::string source_;
  YAML::Node root_;
  std::string error_;
};

}  // namespace sim
