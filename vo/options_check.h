// The pieces every stage's options check (FrontEndOptions::IsValid, TrackerOptions::IsValid, ...)
// is made of: a nested options struct checked under its name, and the first broken rule of the
// struct's own fields as its message.
#pragma once

#include <sstream>
#include <string>
#include <utility>

namespace vo {

// Whether `part` (a nested options struct) is valid; if not, *error (when given) is
// "name: " followed by its message.
template <typename Part>
bool PartIsValid(const Part& part, const char* name, std::string* error) {
  std::string part_error;
  if (part.IsValid(&part_error)) return true;
  if (error) *error = std::string(name) + ": " + part_error;
  return false;
}

// True when `msg` is empty (no rule broken); otherwise false with *error (when given) = msg.
inline bool NoBrokenRule(const std::ostringstream& msg, std::string* error) {
  std::string text = msg.str();
  if (text.empty()) return true;
  if (error) *error = std::move(text);
  return false;
}

}  // namespace vo
