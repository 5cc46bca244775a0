#pragma once
// Test support: a JSON file's content on one line, in a fixed layout that tests can search for
// key-value text: {"k": v, "k2": [a, b]}, integers as integers, other numbers "%.17g" (the same
// double as the file's shortest text), then a newline. What the file says, not how it is spaced.
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>

namespace bd::testing {

inline void append_json_view(std::string& out, const nlohmann::ordered_json& j) {
  if (j.is_object()) {
    out += '{';
    bool first = true;
    for (const auto& [k, v] : j.items()) {
      out += (first ? "" : ", ") + nlohmann::json(k).dump() + ": ";
      append_json_view(out, v);
      first = false;
    }
    out += '}';
  } else if (j.is_array()) {
    out += '[';
    for (std::size_t i = 0; i < j.size(); ++i) {
      if (i) out += ", ";
      append_json_view(out, j[i]);
    }
    out += ']';
  } else if (j.is_number_float()) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.17g", j.get<double>());
    out += buf;
  } else {
    out += j.dump();
  }
}

/// The JSON text `text` in the layout above.
inline std::string json_view(const std::string& text) {
  std::string out;
  append_json_view(out, nlohmann::ordered_json::parse(text));
  return out + "\n";
}

}  // namespace bd::testing
