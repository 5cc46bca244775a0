#pragma once
/// Internal to studies/study/: reading a study file's YAML tree. One Reporter names the file in
/// every mistake (FILE:LINE:COLUMN: message); a MapReader reads one map with its keys checked
/// once (no unknown, no duplicate); read_number() and friends read one value with its path and
/// unit in the message. The loader (load_study.cpp) and each section's reader share them.
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdlib>
#include <string>
#include <utility>
#include <vector>

#include "core/number_text.hpp"
#include "core/types.hpp"
#include "studies/study/load_study.hpp"

namespace bd::studies::detail {

// the largest number of rows a study may ask for (keeps a typo from filling the disk)
inline constexpr double kMaxRows = 1e7;

inline std::string join(const std::vector<std::string>& items) {
  std::string out;
  for (const std::string& s : items) out += (out.empty() ? "" : ", ") + s;
  return out;
}

// what a node holds, in words, for "expected X, got Y"
inline std::string describe(const YAML::Node& n) {
  if (!n.IsDefined() || n.IsNull()) return "nothing";
  if (n.IsSequence()) return "a list";
  if (n.IsMap()) return "a map";
  std::string text = n.Scalar();
  if (text.size() > 40) text = text.substr(0, 37) + "...";
  return "'" + text + "'";
}

// reports mistakes at places in one study file
class Reporter {
 public:
  explicit Reporter(std::string source) : source_(std::move(source)) {}
  const std::string& source() const { return source_; }
  /// Every value read with a unit of its own, as read and in SI ("scene.theta1: 90 deg =
  /// 1.5707963267948966 rad"), in reading order.
  const std::vector<std::string>& units_read() const { return units_read_; }
  void note_unit(const std::string& line) const { units_read_.push_back(line); }

  [[noreturn]] void fail(const YAML::Mark& mark, const std::string& message) const {
    if (mark.is_null()) throw StudyError(source_, 1, 1, message);
    throw StudyError(source_, mark.line + 1, mark.column + 1, message);
  }

 private:
  std::string source_;
  mutable std::vector<std::string> units_read_;  // a log of the reading, not its state
};

// where a value is: its own mark, else its key's (an empty value is marked at the next token,
// often on the next line, so it is reported at its key)
inline YAML::Mark mark_of(const YAML::Node& value, const YAML::Mark& fallback) {
  if (!value.IsDefined() || value.IsNull()) return fallback;
  const YAML::Mark m = value.Mark();
  return m.is_null() ? fallback : m;
}

// a YAML map with its keys checked once: no unknown, no duplicate, all plain names
class MapReader {
 public:
  struct Entry {
    std::string key;
    YAML::Mark key_mark;
    YAML::Node value;
  };

  // `path` names the map in messages ("" for the top level); `where` is the place of the key
  // that introduces it (used for missing keys); `shape` is the expected content, in words
  MapReader(const Reporter& r, const YAML::Node& node, std::string path, const YAML::Mark& where,
            const std::string& shape)
      : r_(r), path_(std::move(path)), where_(where) {
    if (!node.IsMap()) {
      r_.fail(mark_of(node, where_), (path_.empty() ? std::string("a study file") : path_) +
                                         " must be a map " + shape + ", got " + describe(node));
    }
    for (auto it = node.begin(); it != node.end(); ++it) {
      const YAML::Node key = it->first;
      const YAML::Mark km = mark_of(key, where_);
      if (!key.IsScalar()) {
        r_.fail(km, "keys" + in() + " must be plain names, got " + describe(key));
      }
      const std::string name = key.Scalar();
      for (const Entry& e : entries_) {
        if (e.key == name) {
          r_.fail(km, "duplicate key '" + name + "'" + in() + " (first given at line " +
                          std::to_string(e.key_mark.line + 1) + ")");
        }
      }
      entries_.push_back({name, km, it->second});
    }
  }

  // every key must be one of `allowed`; `context` replaces the path in the message if given
  void check_keys(const std::vector<std::string>& allowed, const std::string& context = "") const {
    for (const Entry& e : entries_) {
      bool ok = false;
      for (const std::string& a : allowed) ok = ok || (a == e.key);
      if (!ok) {
        r_.fail(e.key_mark, "unknown key '" + e.key + "'" + (context.empty() ? in() : context) +
                                "; allowed keys: " + join(allowed));
      }
    }
  }

  const Entry* find(const std::string& key) const {
    for (const Entry& e : entries_) {
      if (e.key == key) return &e;
    }
    return nullptr;
  }
  bool has(const std::string& key) const { return find(key) != nullptr; }

  const Entry& require(const std::string& key, const std::string& meaning) const {
    const Entry* e = find(key);
    if (!e) {
      r_.fail(where_, (path_.empty() ? std::string() : path_ + ": ") + "missing required key '" +
                          key + "' (" + meaning + ")");
    }
    return *e;
  }

  std::string full(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }
  const YAML::Mark& where() const { return where_; }
  const std::vector<Entry>& entries() const { return entries_; }

 private:
  std::string in() const { return path_.empty() ? " at the top level" : " in " + path_; }

  const Reporter& r_;
  std::string path_;
  YAML::Mark where_;
  std::vector<Entry> entries_;
};

// The units a value whose SI unit is `si` may be written in, with their factors to SI; a plain
// number is SI. "2 g" is 2 grams for a mass, two standard gravities for an acceleration.
struct UnitFactor {
  const char* name;
  double factor;
  double divisor;  // SI = number · factor / divisor (divided last: 90 deg is π/2 exactly)
};
inline std::vector<UnitFactor> units_for(const std::string& si) {
  constexpr double kPi = 3.14159265358979323846;
  if (si == "rad") return {{"rad", 1, 1}, {"deg", kPi, 180}, {"°", kPi, 180}, {"rev", 2 * kPi, 1}};
  if (si == "rad/s") {
    return {{"rad/s", 1, 1},       {"rpm", 2 * kPi, 60}, {"RPM", 2 * kPi, 60},
            {"rev/s", 2 * kPi, 1}, {"Hz", 2 * kPi, 1},   {"deg/s", kPi, 180}};
  }
  if (si == "m") return {{"m", 1, 1}, {"mm", 1, 1e3}, {"cm", 1, 1e2}, {"in", 0.0254, 1}};
  if (si == "kg") return {{"kg", 1, 1}, {"g", 1, 1e3}, {"lb", 0.45359237, 1}};
  if (si == "kg m²") {
    return {{"kg m²", 1, 1},    {"kg m^2", 1, 1},  {"kg mm^2", 1, 1e6}, {"kg mm²", 1, 1e6},
            {"g cm^2", 1, 1e7}, {"g cm²", 1, 1e7}, {"g mm^2", 1, 1e9},  {"g mm²", 1, 1e9}};
  }
  if (si == "N") return {{"N", 1, 1}, {"kN", 1e3, 1}, {"mN", 1, 1e3}};
  if (si == "N m") return {{"N m", 1, 1}, {"Nm", 1, 1}, {"N mm", 1, 1e3}, {"kN m", 1e3, 1}};
  if (si == "s") return {{"s", 1, 1}, {"ms", 1, 1e3}, {"min", 60, 1}};
  if (si == "m/s") return {{"m/s", 1, 1}, {"mm/s", 1, 1e3}};
  if (si == "m/s²") return {{"m/s²", 1, 1}, {"m/s^2", 1, 1}, {"g", 9.80665, 1}};
  if (si == "Hz") return {{"Hz", 1, 1}, {"rpm", 1, 60}};
  if (si == "N/m") return {{"N/m", 1, 1}, {"N/mm", 1e3, 1}, {"kN/m", 1e3, 1}};
  if (si == "N s/m") return {{"N s/m", 1, 1}, {"N s/mm", 1e3, 1}};
  return {};
}

// a scalar "<number> <unit>" (the space optional) in SI, or false when it is not one; fails at
// the value for a unit the quantity cannot take
inline bool read_with_unit(const Reporter& r, const YAML::Node& node, const YAML::Mark& fallback,
                           const std::string& path, const std::string& si, double& value) {
  if (!node.IsScalar() || si.empty()) return false;
  const std::string& text = node.Scalar();
  const char* begin = text.c_str();
  char* end = nullptr;
  const double number = std::strtod(begin, &end);
  if (end == begin) return false;
  std::string unit(end);
  unit.erase(0, unit.find_first_not_of(' '));
  unit.erase(unit.find_last_not_of(' ') + 1);
  if (unit.empty()) return false;
  std::string known;
  for (const UnitFactor& u : units_for(si)) {
    if (unit == u.name) {
      value = number * u.factor / u.divisor;
      // a value in the SI unit itself is no conversion to note
      if (u.factor != 1 || u.divisor != 1) {
        r.note_unit(path + ": " + text + " = " + text::shortest(value) + " " + si);
      }
      return true;
    }
    known += (known.empty() ? "" : ", ") + std::string(u.name);
  }
  r.fail(mark_of(node, fallback), path + ": unit '" + unit + "' is not one of " + known +
                                      " (a plain number is in " + si + ")");
}

// The range of every number in a study file (but the sweep's seed): 0, or a magnitude from
// kMinMagnitude to kMaxMagnitude. The tool forms products of a few inputs (a counterweight's
// inertia m d^2, a force m l omega^2, its square in an RMS, a disc's radius from its mass and
// thickness); within this range they stay far inside double's range (1e-308 to 1e308), beyond
// it they overflowed to inf or divided by an underflowed 0, and the run failed after `validate`
// said ok (issue 17). 1e15 is beyond any linkage in SI units (a 1e12 kg mass runs); 1e-100 lets
// a script's round-off residue (1.2e-16 for sin(pi)) through and stops subnormals.
inline constexpr double kMaxMagnitude = 1e15;
inline constexpr double kMinMagnitude = 1e-100;

// a finite number in the range above; `unit` in words for messages ("m", "kg", "rad/s", "" for
// none); `bounded` false takes any finite number (the sweep's seed, an integer up to 2^53)
inline double read_number(const Reporter& r, const YAML::Node& node, const YAML::Mark& fallback,
                          const std::string& path, const std::string& unit, bool bounded = true) {
  const std::string in_unit = unit.empty() ? "" : " in " + unit;
  double value = 0.0;
  if (!node.IsScalar() || (!YAML::convert<double>::decode(node, value) &&
                           !read_with_unit(r, node, fallback, path, unit, value))) {
    r.fail(mark_of(node, fallback),
           path + " must be a number" + in_unit + ", got " + describe(node));
  }
  if (!std::isfinite(value)) {
    r.fail(mark_of(node, fallback),
           path + " must be a finite number" + in_unit + ", got " + describe(node));
  }
  const double magnitude = std::fabs(value);
  if (bounded && (magnitude > kMaxMagnitude || (magnitude != 0 && magnitude < kMinMagnitude))) {
    r.fail(mark_of(node, fallback),
           path + " must be 0 or of magnitude 1e-100 to 1e15" + in_unit +
               " (the range the tool computes in), got " + describe(node));
  }
  return value;
}

inline double read_number(const Reporter& r, const MapReader::Entry& e, const std::string& path,
                          const std::string& unit, bool bounded = true) {
  return read_number(r, e.value, e.key_mark, path, unit, bounded);
}

// a finite number > 0
inline double read_positive(const Reporter& r, const MapReader::Entry& e, const std::string& path,
                            const std::string& unit) {
  const double v = read_number(r, e, path, unit);
  if (!(v > 0)) {
    r.fail(mark_of(e.value, e.key_mark),
           path + " must be > 0" + (unit.empty() ? "" : " " + unit) + ", got " + text::shortest(v));
  }
  return v;
}

// a whole number in [lo, hi]
inline int read_count(const Reporter& r, const MapReader::Entry& e, const std::string& path,
                      double lo, double hi) {
  const double v = read_number(r, e, path, "");
  const YAML::Mark m = mark_of(e.value, e.key_mark);
  if (v != std::floor(v)) r.fail(m, path + " must be a whole number, got " + describe(e.value));
  if (v < lo) r.fail(m, path + " must be >= " + text::shortest(lo) + ", got " + text::shortest(v));
  if (v > hi) r.fail(m, path + " must be <= " + text::shortest(hi) + ", got " + text::shortest(v));
  return static_cast<int>(v);
}

inline bool read_bool(const Reporter& r, const MapReader::Entry& e, const std::string& path) {
  bool b = false;
  if (!e.value.IsScalar() || !YAML::convert<bool>::decode(e.value, b)) {
    r.fail(mark_of(e.value, e.key_mark), path + " must be true or false, got " + describe(e.value));
  }
  return b;
}

inline std::string read_text(const Reporter& r, const MapReader::Entry& e,
                             const std::string& path) {
  if (!e.value.IsScalar()) {
    r.fail(mark_of(e.value, e.key_mark), path + " must be text, got " + describe(e.value));
  }
  return e.value.Scalar();
}

// [x, y] with each element checked; element marks go to `marks` when given
inline Vec2 read_vec2(const Reporter& r, const MapReader::Entry& e, const std::string& path,
                      const std::string& unit, YAML::Mark marks[2]) {
  const YAML::Mark m = mark_of(e.value, e.key_mark);
  if (!e.value.IsSequence() || e.value.size() != 2) {
    r.fail(m, path + " must be a list of 2 numbers [x, y] in " + unit + ", got " +
                  (e.value.IsSequence() ? "a list of " + std::to_string(e.value.size())
                                        : describe(e.value)));
  }
  Vec2 v;
  for (std::size_t i = 0; i < 2; ++i) {
    const YAML::Node item = e.value[i];
    marks[i] = mark_of(item, m);
    v[static_cast<Eigen::Index>(i)] =
        read_number(r, item, m, path + "[" + std::to_string(i) + "]", unit);
  }
  return v;
}

// A link's centre of mass in a study file: exactly one complete pair, {s, sigma} or {e, f}.
struct CentreOfMassKeys {
  const MapReader::Entry *s, *sigma, *e, *f;
  bool polar() const { return s != nullptr; }
};
// The pair `m` (the link at `path`, its entry `link`) gives; a mistake is reported at its key:
// both pairs given (at the later pair), half a pair (at the half), none (at the link, with
// `missing`, what to give).
inline CentreOfMassKeys centre_of_mass_keys(const Reporter& r, const MapReader& m,
                                            const MapReader::Entry& link, const std::string& path,
                                            const std::string& missing) {
  const CentreOfMassKeys k{m.find("s"), m.find("sigma"), m.find("e"), m.find("f")};
  auto first_of = [](const MapReader::Entry* a, const MapReader::Entry* b) {
    if (!a || !b) return a ? a : b;
    return a->key_mark.pos <= b->key_mark.pos ? a : b;
  };
  const MapReader::Entry* polar = first_of(k.s, k.sigma);
  const MapReader::Entry* cart = first_of(k.e, k.f);
  if (polar && cart) {
    r.fail((polar->key_mark.pos > cart->key_mark.pos ? polar : cart)->key_mark,
           path + " gives its centre of mass both as {s, sigma} and as {e, f}; give one pair only");
  }
  if (!polar && !cart) r.fail(link.key_mark, path + ": missing the centre of mass; " + missing);
  const std::pair<const MapReader::Entry*, const char*> halves[][2] = {
      {{k.s, "s"}, {k.sigma, "sigma"}}, {{k.e, "e"}, {k.f, "f"}}};
  for (const auto& pair : halves) {
    for (int i = 0; i < 2; ++i) {
      const auto& [given, name] = pair[i];
      const char* other = pair[1 - i].second;
      if (given && !pair[1 - i].first) {
        r.fail(given->key_mark, path + "." + name + " is given without " + other + "; give both " +
                                    name + " and " + other);
      }
    }
  }
  return k;
}

}  // namespace bd::studies::detail
