// The one check for every name that becomes a path component of an output folder: scenario
// names (out/run/<name>, out/match_eval/<name>, suite run ids), suite names
// (out/suite/<name>), suite configuration names (run ids), tune names (out/tune/<name>),
// dataset folder names (out/run/<folder>, out/eval/<folder>) and suite shard tags
// (<out>/tmp/<tag>).
#pragma once

#include <string>

namespace harness {

// Longest name accepted (bytes): NAME_MAX of common Linux file systems.
constexpr size_t kMaxPathNameBytes = 255;

// True when `name` is usable as one folder name inside an output folder: not empty, at most
// kMaxPathNameBytes bytes, not "." and without "..", no '/' or '\', no leading '-' (it would
// read as an option), no control characters (bytes < 0x20 and 0x7f). Otherwise false and
// *error = "<what> '<name>': cannot name a folder: <the rule broken>"; control characters are
// shown escaped (\x01) so the message stays on one line.
bool CheckPathName(const std::string& name, const std::string& what, std::string* error);

}  // namespace harness
