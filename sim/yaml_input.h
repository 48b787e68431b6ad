// Reading input files the strict way: a whole text file (a folder, a missing or unreadable path
// is an error that names it) and a YAML document whose mappings have no duplicate keys.
// Every YAML reader of vobench goes through LoadYamlDocument: scenarios (sim/scenario.cc), VO
// configs (harness/vo_config.cc), suites (harness/suite.cc), tune files (harness/tune.cc) and the
// EuRoC sensor.yaml (harness/dataset.cc). It lives in sim/ because harness/ depends on sim/.
#pragma once

#include <yaml-cpp/yaml.h>

#include <string>

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

}  // namespace sim
