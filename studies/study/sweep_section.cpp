// The sweep section: the design of points and each parameter's path, checked against the study
// file's own tree (so a path names a value the file states).
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "studies/study/load_study_internal.hpp"
#include "studies/study/sections.hpp"
#include "studies/study/yaml_reader.hpp"

namespace bd::studies::detail {

namespace {

// most points a sweep may have (a 1000 x 1000 grid), and most parallel runs it may ask for
constexpr double kMaxSweepPoints = 1e6;
constexpr double kMaxSweepThreads = 1024;
// a sweep's seed is a whole number below 2^53: every such number reads back exactly from its text
constexpr double kSeedLimit = 9007199254740992.0;

// a grid parameter's `count` values from `from` to `to`: from + (to - from) k / (count - 1),
// or geometrically spaced (evenly in log) with log_scale; both ends exact
std::vector<double> spaced_values(double from, double to, int count, bool log_scale) {
  std::vector<double> v(static_cast<std::size_t>(count));
  const double a = log_scale ? std::log(from) : from;
  const double b = log_scale ? std::log(to) : to;
  for (int k = 0; k < count; ++k) {
    const double x = a + (b - a) * k / (count - 1);
    v[static_cast<std::size_t>(k)] = log_scale ? std::exp(x) : x;
  }
  v.front() = from;
  v.back() = to;
  return v;
}

class SweepReader {
 public:
  explicit SweepReader(const Reporter& r) : r_(r) {}

  // sweep: {design, points, seed, threads, parameters}; each path is checked against `root`, the
  // study file's tree
  SweepRequest read_sweep(const MapReader::Entry& e, const YAML::Node& root) {
    SweepRequest req;
    const MapReader s(r_, e.value, "sweep", e.key_mark,
                      "(design, points, seed, threads, parameters)");
    s.check_keys({"design", "points", "seed", "threads", "parameters"});
    if (const MapReader::Entry* d = s.find("design")) {
      const std::string t = read_text(r_, *d, "sweep.design");
      if (t == "grid") {
        req.design = SweepDesign::kGrid;
      } else if (t == "random") {
        req.design = SweepDesign::kRandom;
      } else if (t == "lhs") {
        req.design = SweepDesign::kLatinHypercube;
      } else {
        r_.fail(mark_of(d->value, d->key_mark),
                "sweep.design must be grid, random or lhs, got " + describe(d->value));
      }
    }
    const bool grid = req.design == SweepDesign::kGrid;
    const std::string design = to_string(req.design);
    if (grid) {
      // a grid's points follow from its parameters; a stray key would be silently unused
      for (const char* key : {"points", "seed"}) {
        if (const MapReader::Entry* x = s.find(key)) {
          r_.fail(x->key_mark, std::string("sweep.") + key +
                                   " is used only by the random and lhs designs (a grid's "
                                   "points are all combinations of its parameters' values)");
        }
      }
    } else {
      req.points =
          read_count(r_, s.require("points", "how many points the " + design + " design draws"),
                     "sweep.points", 1, kMaxSweepPoints);
      if (const MapReader::Entry* x = s.find("seed")) req.seed = read_seed(*x);
    }
    if (const MapReader::Entry* x = s.find("threads")) {
      req.threads = read_count(r_, *x, "sweep.threads", 0, kMaxSweepThreads);
    }

    const MapReader::Entry& list =
        s.require("parameters", "the study values to vary, each with its path");
    const YAML::Mark lm = mark_of(list.value, list.key_mark);
    if (!list.value.IsSequence() || list.value.size() == 0) {
      r_.fail(lm,
              "sweep.parameters must be a list of one or more parameters (each a map with "
              "path, and values or from and to), got " +
                  (list.value.IsSequence() ? std::string("an empty list") : describe(list.value)));
    }
    std::vector<int> path_lines;
    std::vector<YAML::Node> targets;  // the value each path names
    for (std::size_t i = 0; i < list.value.size(); ++i) {
      YAML::Mark path_mark;
      YAML::Node target;
      SweepParameter p =
          read_sweep_parameter(list.value[i], i, req.design, root, lm, path_mark, target);
      for (std::size_t k = 0; k < req.parameters.size(); ++k) {
        const std::string head = "sweep.parameters[" + std::to_string(i) + "].path: " + p.path;
        const std::string other = "sweep.parameters[" + std::to_string(k) + "]";
        const std::string line = "line " + std::to_string(path_lines[k]);
        if (req.parameters[k].path == p.path) {
          r_.fail(path_mark, head + " is already swept by " + other + " (" + line +
                                 "); each path may be swept once");
        }
        // two paths to one node (a YAML alias): setting one would set the other
        if (targets[k].is(target)) {
          r_.fail(path_mark, head + " is the same value as " + other + "'s " +
                                 req.parameters[k].path + " (" + line +
                                 "), through a YAML alias; each value may be swept once");
        }
      }
      req.parameters.push_back(std::move(p));
      path_lines.push_back(path_mark.line + 1);
      targets.push_back(target);
    }
    if (grid) {
      double n = 1;
      std::string product;
      for (const SweepParameter& p : req.parameters) {
        n *= static_cast<double>(p.values.size());
        product += (product.empty() ? "" : " x ") + std::to_string(p.values.size());
      }
      if (n > kMaxSweepPoints) {
        r_.fail(list.key_mark, "sweep: the grid has " + product + " = " + text::shortest(n) +
                                   " points, more than the " + text::shortest(kMaxSweepPoints) +
                                   " a sweep may have");
      }
      req.points = static_cast<int>(n);
    }
    return req;
  }

  // sweep.seed: a whole number that reads back exactly
  std::uint64_t read_seed(const MapReader::Entry& e) {
    const double v = read_number(r_, e, "sweep.seed", "", false);
    if (v != std::floor(v) || v < 0 || v >= kSeedLimit) {
      r_.fail(mark_of(e.value, e.key_mark),
              "sweep.seed must be a whole number from 0 to 2^53 - 1 (9007199254740991), got " +
                  describe(e.value));
    }
    return static_cast<std::uint64_t>(v);
  }

  // one entry of sweep.parameters: {path, values | from, to, count, scale}; `path_mark` gets
  // the place of its path, `target` the node it names
  SweepParameter read_sweep_parameter(const YAML::Node& node, std::size_t i, SweepDesign design,
                                      const YAML::Node& root, const YAML::Mark& list_mark,
                                      YAML::Mark& path_mark, YAML::Node& target) {
    const std::string where = "sweep.parameters[" + std::to_string(i) + "]";
    const YAML::Mark at = mark_of(node, list_mark);
    SweepParameter p;
    p.line = at.line + 1;
    p.column = at.column + 1;
    const MapReader m(r_, node, where, at, "(path, and values or from, to, count; scale)");
    m.check_keys({"path", "values", "from", "to", "count", "scale"});
    const MapReader::Entry& pe =
        m.require("path", "the study value to vary, e.g. linkage.coupler.mass");
    p.path = read_text(r_, pe, where + ".path");
    path_mark = mark_of(pe.value, pe.key_mark);
    target.reset(sweep_target(p.path, root, path_mark, where + ".path"));

    if (const MapReader::Entry* sc = m.find("scale")) {
      const std::string t = read_text(r_, *sc, where + ".scale");
      if (t != "linear" && t != "log") {
        r_.fail(mark_of(sc->value, sc->key_mark),
                where + ".scale must be linear or log, got " + describe(sc->value));
      }
      p.log_scale = t == "log";
    }
    const MapReader::Entry* values = m.find("values");
    const MapReader::Entry* count = m.find("count");
    if (design != SweepDesign::kGrid) {
      // random and lhs draw their values in [from, to)
      for (const MapReader::Entry* x : {values, count}) {
        if (x) {
          r_.fail(x->key_mark, where + "." + x->key + ": the " + to_string(design) +
                                   " design draws its values; give from and to only");
        }
      }
    } else if (values) {
      for (const char* key : {"from", "to", "count"}) {
        const MapReader::Entry* x = m.find(key);
        if (!x) continue;
        const MapReader::Entry* later = x->key_mark.pos > values->key_mark.pos ? x : values;
        r_.fail(later->key_mark, where + ": give either values or from, to and count, not both");
      }
      p.values = read_sweep_values(*values, where, p.log_scale);
      const auto [lo, hi] = std::minmax_element(p.values.begin(), p.values.end());
      p.from = *lo;
      p.to = *hi;
      return p;
    } else {
      for (const char* key : {"from", "to", "count"}) {
        if (m.has(key)) continue;
        r_.fail(at, where +
                        ": a grid parameter needs values: [...] or from, to and count; "
                        "missing '" +
                        key + "'");
      }
    }

    const MapReader::Entry& from = m.require("from", "the lower end of the range");
    const MapReader::Entry& to = m.require("to", "the upper end of the range");
    check_plain(from.value, from.key_mark, where + ".from");
    check_plain(to.value, to.key_mark, where + ".to");
    p.from = read_number(r_, from, where + ".from", "");
    p.to = read_number(r_, to, where + ".to", "");
    if (!(p.from < p.to)) {
      r_.fail(mark_of(to.value, to.key_mark),
              where + ": from must be < to, got from = " + text::shortest(p.from) +
                  ", to = " + text::shortest(p.to));
    }
    if (p.log_scale && !(p.from > 0)) {
      r_.fail(mark_of(from.value, from.key_mark),
              where + ".from must be > 0 with scale: log, got " + text::shortest(p.from));
    }
    if (design == SweepDesign::kGrid) {
      const int n = read_count(r_, *count, where + ".count", 2, kMaxSweepPoints);
      p.values = spaced_values(p.from, p.to, n, p.log_scale);
      for (std::size_t k = 1; k < p.values.size(); ++k) {
        if (p.values[k] > p.values[k - 1]) continue;
        r_.fail(mark_of(count->value, count->key_mark),
                where + ".count: " + std::to_string(n) + " values from " + text::shortest(p.from) +
                    " to " + text::shortest(p.to) +
                    " are not distinct in double precision; give fewer");
      }
    }
    return p;
  }

  // a grid parameter's `values`: a non-empty list of distinct finite numbers (> 0 with log)
  std::vector<double> read_sweep_values(const MapReader::Entry& e, const std::string& where,
                                        bool log_scale) {
    const std::string path = where + ".values";
    const YAML::Mark vm = mark_of(e.value, e.key_mark);
    if (!e.value.IsSequence() || e.value.size() == 0) {
      r_.fail(vm, path + " must be a list of one or more numbers, got " +
                      (e.value.IsSequence() ? std::string("an empty list") : describe(e.value)));
    }
    std::vector<double> values;
    for (std::size_t k = 0; k < e.value.size(); ++k) {
      const YAML::Node item = e.value[k];
      const std::string ip = path + "[" + std::to_string(k) + "]";
      check_plain(item, vm, ip);
      const double v = read_number(r_, item, vm, ip, "");
      if (log_scale && !(v > 0)) {
        r_.fail(mark_of(item, vm), ip + " must be > 0 with scale: log, got " + text::shortest(v));
      }
      for (std::size_t j = 0; j < values.size(); ++j) {
        if (values[j] != v) continue;
        r_.fail(mark_of(item, vm), ip + " repeats values[" + std::to_string(j) + "] (" +
                                       text::shortest(v) + "); a grid's values must be distinct");
      }
      values.push_back(v);
    }
    return values;
  }

  // the node `path` (the value of `key`, at `m`) names: a number the study file states,
  // outside the sweep section; a mistake is reported with what the file has where the path goes
  // astray
  YAML::Node sweep_target(const std::string& path, const YAML::Node& root, const YAML::Mark& m,
                          const std::string& key) {
    const std::string head = key + ": ";
    const auto steps = internal::parse_path(path);
    if (!steps) {
      r_.fail(m, head + "'" + path +
                     "' is not a path; give map keys joined by '.' and a list element by [i], "
                     "e.g. linkage.coupler.mass or loads.crank.force[1]");
    }
    const std::string& first = steps->front().key;
    if (first == "sweep") {
      r_.fail(m, head + path + " is in the sweep section itself; sweep a value of the study");
    }
    if (first == "name" && steps->size() == 1) {
      r_.fail(m, head + "name is the study's name (text), not a number to sweep");
    }
    YAML::Node node;
    node.reset(root);
    std::string at;  // the path walked so far, "" at the top
    for (const internal::PathStep& st : *steps) {
      const std::string here = at.empty() ? "the study file" : at;
      YAML::Node next;
      if (!st.key.empty()) {
        if (!node.IsMap()) {
          r_.fail(m, head + here + " is " + what_is(node) + ", not a map, so it has no key '" +
                         st.key + "'");
        }
        std::vector<std::string> keys;
        bool found = false;
        for (auto it = node.begin(); it != node.end(); ++it) {
          keys.push_back(it->first.Scalar());
          if (!found && it->first.Scalar() == st.key) {
            next.reset(it->second);
            found = true;
          }
        }
        if (!found) {
          r_.fail(m, head + here + " has no key '" + st.key + "' (it has " + join(keys) + ")");
        }
        at += (at.empty() ? "" : ".") + st.key;
      } else {
        const std::string index = "[" + std::to_string(st.index) + "]";
        if (!node.IsSequence()) {
          r_.fail(m, head + here + " is " + what_is(node) + ", not a list, so it has no element " +
                         index);
        }
        if (st.index >= node.size()) {
          r_.fail(m, head + here + " has no element " + index + " (it is " + what_is(node) +
                         ": [0] to [" + std::to_string(node.size() - 1) + "])");
        }
        next.reset(node[st.index]);
        at += index;
      }
      node.reset(next);
    }
    // where it leads: a number the study states (in SI or with a unit of its own: the sweep's
    // plain SI values take its place)
    double v = 0.0;
    if (node.IsScalar() && YAML::convert<double>::decode(node, v) && std::isfinite(v)) {
      return node;
    }
    if (with_unit(node)) return node;
    std::string hint;
    if (node.IsMap() && node.size() > 0) {
      hint = "; name one of its values, e.g. " + path + "." + node.begin()->first.Scalar();
    } else if (node.IsSequence() && node.size() > 0) {
      hint = "; name an element, e.g. " + path + "[0]";
    }
    r_.fail(m, head + path + " is " + what_is(node) + ", not a " +
                   (node.IsScalar() && YAML::convert<double>::decode(node, v) ? "finite " : "") +
                   "number" + hint);
  }

  // a number with a unit after it ("300 rpm"), as the study's values may be written
  static bool with_unit(const YAML::Node& n) {
    if (!n.IsScalar()) return false;
    const char* begin = n.Scalar().c_str();
    char* end = nullptr;
    const double v = std::strtod(begin, &end);
    return end != begin && std::isfinite(v) && *end == ' ' &&
           std::string(end).find_first_not_of(' ') != std::string::npos;
  }

  // a swept value is a plain number in SI units: one written with a unit is refused as such
  void check_plain(const YAML::Node& n, const YAML::Mark& fallback, const std::string& path) const {
    if (!with_unit(n)) return;
    r_.fail(mark_of(n, fallback),
            path +
                ": the swept values are plain numbers in SI units (rad, m, kg, s, N, rad/s, ...), "
                "got " +
                describe(n) + "; the value the path names may carry a unit of its own");
  }

  // what a node is, for "X is ..., not a number"
  static std::string what_is(const YAML::Node& n) {
    if (n.IsMap()) {
      std::vector<std::string> keys;
      for (auto it = n.begin(); it != n.end(); ++it) keys.push_back(it->first.Scalar());
      return keys.empty() ? "an empty map" : "a map (with keys " + join(keys) + ")";
    }
    if (n.IsSequence()) {
      return n.size() == 0 ? "an empty list" : "a list of " + std::to_string(n.size());
    }
    if (n.IsScalar()) return describe(n);
    return "empty";
  }

 private:
  const Reporter& r_;
};

}  // namespace

SweepRequest read_sweep(const Reporter& r, const MapReader::Entry& e, const YAML::Node& root) {
  return SweepReader(r).read_sweep(e, root);
}

}  // namespace bd::studies::detail
