#include "harness/path_names.h"

#include <cstdio>

namespace harness {
namespace {

// The name with control characters escaped, so that a message stays printable and on one line.
std::string Printable(const std::string& name) {
  std::string out;
  for (const char c : name) {
    const unsigned char u = static_cast<unsigned char>(c);
    if (u < 0x20 || u == 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof(buf), "\\x%02x", u);
      out += buf;
    } else {
      out += c;
    }
  }
  return out;
}

}  // namespace

bool CheckPathName(const std::string& name, const std::string& what, std::string* error) {
  const char* problem = nullptr;
  if (name.empty()) {
    problem = "empty";
  } else if (name.size() > kMaxPathNameBytes) {
    problem = "longer than 255 bytes";
  } else if (name == ".") {
    problem = "'.' is the folder itself";
  } else if (name.find("..") != std::string::npos) {
    problem = "contains '..'";
  } else if (name.find('/') != std::string::npos || name.find('\\') != std::string::npos) {
    problem = "contains a path separator ('/' or '\\')";
  } else if (name[0] == '-') {
    problem = "starts with '-'";
  } else {
    for (const char c : name) {
      const unsigned char u = static_cast<unsigned char>(c);
      if (u < 0x20 || u == 0x7f) problem = "contains a control character";
    }
  }
  if (!problem) return true;
  if (error) *error = what + " '" + Printable(name) + "': cannot name a folder: " + problem;
  return false;
}

}  // namespace harness
