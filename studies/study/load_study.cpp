#include "studies/study/load_study.hpp"

#include <fmt/printf.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string_view>
#include <utility>
#include <vector>

#include "core/fourbar/kinematics.hpp"
#include "core/number_text.hpp"
#include "optimize/nlp.hpp"
#include "optimize/optimize.hpp"
#include "studies/study/load_study_internal.hpp"

namespace bd::studies {

StudyError::StudyError(std::string file, int line, int column, std::string message)
    : InputError(line > 0 ? file + ":" + std::to_string(line) + ":" + std::to_string(column) +
                                ": " + message
                          : file + ": " + message),
      file_(std::move(file)),
      line_(line),
      column_(column),
      message_(std::move(message)) {}

namespace {

// largest number of rows a study may ask for (keeps a typo from filling the disk)
constexpr double kMaxRows = 1e7;
// longest study name, and what the balanced design's study appends to it
constexpr std::size_t kMaxName = 100;
constexpr std::string_view kBalancedSuffix = "-balanced";
constexpr std::string_view kOptimizedSuffix = "-optimized";
// most points a sweep may have (a 1000 x 1000 grid), and most parallel runs it may ask for
constexpr double kMaxSweepPoints = 1e6;
constexpr double kMaxSweepThreads = 1024;
// a sweep's seed is a whole number below 2^53: every such number reads back exactly from its text
constexpr double kSeedLimit = 9007199254740992.0;

std::string join(const std::vector<std::string>& items) {
  std::string out;
  for (const std::string& s : items) out += (out.empty() ? "" : ", ") + s;
  return out;
}

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

// what a node holds, in words, for "expected X, got Y"
std::string describe(const YAML::Node& n) {
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

  [[noreturn]] void fail(const YAML::Mark& mark, const std::string& message) const {
    if (mark.is_null()) throw StudyError(source_, 1, 1, message);
    throw StudyError(source_, mark.line + 1, mark.column + 1, message);
  }

 private:
  std::string source_;
};

// where a value is: its own mark, else its key's (an empty value is marked at the next token,
// often on the next line, so it is reported at its key)
YAML::Mark mark_of(const YAML::Node& value, const YAML::Mark& fallback) {
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

// a finite number; `unit` in words for messages ("m", "kg", "rad/s", "" for none)
double read_number(const Reporter& r, const YAML::Node& node, const YAML::Mark& fallback,
                   const std::string& path, const std::string& unit) {
  const std::string in_unit = unit.empty() ? "" : " in " + unit;
  double value = 0.0;
  if (!node.IsScalar() || !YAML::convert<double>::decode(node, value)) {
    r.fail(mark_of(node, fallback),
           path + " must be a number" + in_unit + ", got " + describe(node));
  }
  if (!std::isfinite(value)) {
    r.fail(mark_of(node, fallback),
           path + " must be a finite number" + in_unit + ", got " + describe(node));
  }
  return value;
}

double read_number(const Reporter& r, const MapReader::Entry& e, const std::string& path,
                   const std::string& unit) {
  return read_number(r, e.value, e.key_mark, path, unit);
}

// a whole number in [lo, hi]
int read_count(const Reporter& r, const MapReader::Entry& e, const std::string& path, double lo,
               double hi) {
  const double v = read_number(r, e, path, "");
  const YAML::Mark m = mark_of(e.value, e.key_mark);
  if (v != std::floor(v)) r.fail(m, path + " must be a whole number, got " + describe(e.value));
  if (v < lo) r.fail(m, path + " must be >= " + text::exact(lo) + ", got " + text::exact(v));
  if (v > hi) r.fail(m, path + " must be <= " + text::exact(hi) + ", got " + text::exact(v));
  return static_cast<int>(v);
}

std::string read_text(const Reporter& r, const MapReader::Entry& e, const std::string& path) {
  if (!e.value.IsScalar()) {
    r.fail(mark_of(e.value, e.key_mark), path + " must be text, got " + describe(e.value));
  }
  return e.value.Scalar();
}

// [x, y] with each element checked; element marks go to `marks` when given
Vec2 read_vec2(const Reporter& r, const MapReader::Entry& e, const std::string& path,
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

// the links that can carry a counterweight or a counter-rotation, pivots A0 and A3
constexpr const char* kSides[] = {"crank", "rocker"};

// where each quantity make_fourbar() may complain about sits in the file
struct Place {
  std::string core_name;   // as make_fourbar() names it ("coupler.mass")
  std::string study_path;  // as the study file names it ("linkage.coupler.mass")
  YAML::Mark mark;
};

class StudyParser {
 public:
  explicit StudyParser(const Reporter& r) : r_(r) {}

  Study parse(const YAML::Node& root) {
    Study study;
    study.source = r_.source();
    if (!root.IsDefined() || root.IsNull()) {
      r_.fail(YAML::Mark(),
              "the study file is empty; expected the keys name, linkage and scene "
              "(and optionally loads, method, tolerance)");
    }
    const MapReader top(r_, root, "", mark_of(root, YAML::Mark()),
                        "of keys (name, linkage, scene, ...)");
    top.check_keys({"name", "linkage", "loads", "scene", "method", "tolerance", "balance",
                    "optimize", "sweep"});

    const MapReader::Entry& name = top.require("name", "the study's name, used in output names");
    study.name = read_name(name);

    const MapReader::Entry& linkage = top.require("linkage", "the mechanism");
    core::FourBar model = read_linkage(linkage);
    if (const MapReader::Entry* loads = top.find("loads")) model.loads = read_loads(*loads);
    study.model = checked_model(model, linkage.key_mark);

    const MapReader::Entry& scene = top.require("scene", "what to simulate: free or driven");
    study.scene = read_scene(scene);
    check_assembly(study.model, study.scene, scene.key_mark);

    if (const MapReader::Entry* method = top.find("method")) {
      study.formulation = read_method(*method);
    }
    if (const MapReader::Entry* tol = top.find("tolerance")) {
      study.tolerance = read_tolerance(*tol);
    }
    if (const MapReader::Entry* balance = top.find("balance")) {
      // the balanced design is written as a study named <name>-balanced
      if (study.name.size() > kMaxName - kBalancedSuffix.size()) {
        r_.fail(mark_of(name.value, name.key_mark),
                "name must have at most " + std::to_string(kMaxName - kBalancedSuffix.size()) +
                    " characters in a study with a balance section (balanced.yaml is named "
                    "<name>" +
                    std::string(kBalancedSuffix) + "), got " + std::to_string(study.name.size()));
      }
      study.balance = read_balance(*balance, study.model);
    }
    if (const MapReader::Entry* opt = top.find("optimize")) {
      // one or the other: a balanced design and an optimised one would compete for the outputs
      if (const MapReader::Entry* balance = top.find("balance")) {
        const bool later = opt->key_mark.pos > balance->key_mark.pos;
        const MapReader::Entry& second = later ? *opt : *balance;
        const MapReader::Entry& first = later ? *balance : *opt;
        r_.fail(second.key_mark,
                "a study has a balance section or an optimize section, not both (" + first.key +
                    " is given at line " + std::to_string(first.key_mark.line + 1) +
                    "); to optimise a balanced design, ask for force_balance "
                    "in optimize.constraints");
      }
      // the optimised design is written as a study named <name>-optimized
      if (study.name.size() > kMaxName - kOptimizedSuffix.size()) {
        r_.fail(mark_of(name.value, name.key_mark),
                "name must have at most " + std::to_string(kMaxName - kOptimizedSuffix.size()) +
                    " characters in a study with an optimize section (optimized.yaml is named "
                    "<name>" +
                    std::string(kOptimizedSuffix) + "), got " + std::to_string(study.name.size()));
      }
      study.optimize = read_optimize(*opt, study);
    }
    // last: the study above is the sweep's base, valid on its own; the paths are checked
    // against the file's tree
    if (const MapReader::Entry* sweep = top.find("sweep")) study.sweep = read_sweep(*sweep, root);
    return study;
  }

 private:
  std::string read_name(const MapReader::Entry& e) {
    const std::string name = read_text(r_, e, "name");
    const YAML::Mark m = mark_of(e.value, e.key_mark);
    if (name.empty() || name.size() > kMaxName) {
      r_.fail(m, "name must have 1 to " + std::to_string(kMaxName) + " characters, got " +
                     std::to_string(name.size()));
    }
    for (char c : name) {
      const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                      c == '.' || c == '_' || c == '-';
      if (!ok) {
        r_.fail(m,
                "name may use only letters, digits, '.', '_' and '-' (it names the output "
                "directory), got " +
                    describe(e.value));
      }
    }
    if (name[0] == '.') r_.fail(m, "name must not start with '.', got " + describe(e.value));
    return name;
  }

  core::FourBar read_linkage(const MapReader::Entry& e) {
    const MapReader lk(r_, e.value, "linkage", e.key_mark,
                       "(type, frame, branch, crank, coupler, rocker)");
    lk.check_keys({"type", "frame", "branch", "crank", "coupler", "rocker", "counter_rotations"});

    const MapReader::Entry& type = lk.require("type", "the kind of linkage: fourbar");
    const std::string t = read_text(r_, type, "linkage.type");
    if (t != "fourbar") {
      r_.fail(mark_of(type.value, type.key_mark),
              "linkage.type '" + t + "' is not supported; expected fourbar");
    }

    core::FourBar model;
    const MapReader::Entry& frame = lk.require("frame", "l4, the distance A0A3 in m");
    model.frame_length = read_number(r_, frame, "linkage.frame", "m");
    places_.push_back({"frame", "linkage.frame", mark_of(frame.value, frame.key_mark)});

    const MapReader::Entry& branch = lk.require("branch", "the assembly mode, +1 or -1");
    const double b = read_number(r_, branch, "linkage.branch", "");
    if (b != 1.0 && b != -1.0) {
      r_.fail(mark_of(branch.value, branch.key_mark),
              "linkage.branch must be +1 or -1, got " + describe(branch.value));
    }
    model.branch = b > 0 ? core::Branch::kPlus : core::Branch::kMinus;
    places_.push_back({"branch", "linkage.branch", mark_of(branch.value, branch.key_mark)});

    model.crank = read_link(lk, "crank");
    model.coupler = read_link(lk, "coupler");
    model.rocker = read_link(lk, "rocker");
    if (const MapReader::Entry* cr = lk.find("counter_rotations")) {
      model.counter_rotations = read_counter_rotations(*cr, model.frame_length);
    }
    return model;
  }

  // linkage.counter_rotations: {crank: {inertia, at}, rocker: {inertia, at}}, each optional
  core::CounterRotations read_counter_rotations(const MapReader::Entry& e, double frame) {
    core::CounterRotations out;
    if (e.value.IsNull()) return out;
    const MapReader cr(r_, e.value, "linkage.counter_rotations", e.key_mark, "(crank, rocker)");
    cr.check_keys({"crank", "rocker"});
    core::CounterRotation* targets[] = {&out.crank, &out.rocker};
    for (int i = 0; i < 2; ++i) {
      const std::string side = kSides[i];
      const MapReader::Entry* x = cr.find(side);
      if (!x) continue;
      const std::string path = "linkage.counter_rotations." + side;
      const MapReader m(r_, x->value, path, x->key_mark, "(inertia, at)");
      m.check_keys({"inertia", "at"});
      const MapReader::Entry& j = m.require("inertia", "J of the disc about its shaft in kg m^2");
      targets[i]->inertia = read_number(r_, j, path + ".inertia", "kg m^2");
      places_.push_back({"counter_rotations." + side + ".inertia", path + ".inertia",
                         mark_of(j.value, j.key_mark)});
      const MapReader::Entry& at = m.require("at", "the shaft position [x, y] on the frame in m");
      targets[i]->at = read_shaft(at, path + ".at", i, frame);
    }
    return out;
  }

  // a counter-rotation shaft position [x, y] on the frame, away from its link's pivot
  Vec2 read_shaft(const MapReader::Entry& at, const std::string& path, int side, double frame) {
    YAML::Mark marks[2];
    const Vec2 p = read_vec2(r_, at, path, "m", marks);
    const Vec2 pivot = side == 0 ? Vec2(0, 0) : Vec2(frame, 0);
    if (p == pivot) {
      const std::string buf =
          fmt::sprintf("'s pivot %s = (%.10g, %.10g) m, got [%.10g, %.10g]",
                       side == 0 ? "A0" : "A3", pivot.x(), pivot.y(), p.x(), p.y());
      r_.fail(mark_of(at.value, at.key_mark), path + " must differ from the " + kSides[side] + buf);
    }
    return p;
  }

  // balance: {force, moment, counterweights, counter_rotations}, then the synthesis itself
  balance::BalancedDesign read_balance(const MapReader::Entry& e, const core::FourBar& model) {
    balance::BalanceRequest request;
    YAML::Mark force_mark = e.key_mark, moment_mark = e.key_mark;
    if (!e.value.IsNull()) {  // `balance:` with nothing under it: the defaults
      const MapReader b(r_, e.value, "balance", e.key_mark,
                        "(force, moment, counterweights, counter_rotations)");
      b.check_keys({"force", "moment", "counterweights", "counter_rotations"});
      if (const MapReader::Entry* f = b.find("force")) {
        request.force = read_full_or_none(*f, "balance.force");
        force_mark = mark_of(f->value, f->key_mark);
      }
      if (const MapReader::Entry* m = b.find("moment")) {
        request.moment = read_full_or_none(*m, "balance.moment");
        moment_mark = mark_of(m->value, m->key_mark);
      }
      if (request.moment && !request.force) {
        r_.fail(moment_mark,
                "balance.moment: full needs balance.force: full (a moment balance starts from a "
                "force-balanced design)");
      }
      if (const MapReader::Entry* cw = b.find("counterweights")) {
        if (!request.force) {
          r_.fail(cw->key_mark, "balance.counterweights are used only with balance.force: full");
        }
        read_counterweights(*cw, request);
      }
      if (const MapReader::Entry* cr = b.find("counter_rotations")) {
        if (!request.moment) {
          r_.fail(cr->key_mark,
                  "balance.counter_rotations are used only with balance.moment: full");
        }
        read_shafts(*cr, model.frame_length, request);
      }
    }
    // the synthesis: its complaint is reported at the key that asked for it
    try {
      return balance::balance_design(model, request);
    } catch (const balance::SynthesisError& err) {
      if (err.step() == balance::SynthesisError::Step::kMoment) {
        r_.fail(moment_mark, std::string("balance.moment: full is not possible: ") + err.what());
      }
      r_.fail(force_mark, std::string("balance.force: full is not possible: ") + err.what());
    }
  }

  bool read_full_or_none(const MapReader::Entry& e, const std::string& path) {
    const std::string v = read_text(r_, e, path);
    if (v != "full" && v != "none") {
      r_.fail(mark_of(e.value, e.key_mark),
              path + " must be full or none, got " + describe(e.value));
    }
    return v == "full";
  }

  void read_counterweights(const MapReader::Entry& e, balance::BalanceRequest& request) {
    if (e.value.IsNull()) return;
    const MapReader cw(r_, e.value, "balance.counterweights", e.key_mark, "(crank, rocker)");
    cw.check_keys({"crank", "rocker"});
    if (const MapReader::Entry* c = cw.find("crank")) {
      request.crank_counterweight = read_counterweight(*c, "balance.counterweights.crank");
    }
    if (const MapReader::Entry* r = cw.find("rocker")) {
      request.rocker_counterweight = read_counterweight(*r, "balance.counterweights.rocker");
    }
  }

  // {shape, mass | distance | radius, thickness, density}

  // `shape: point | disc` of a counterweight at `path`
  balance::CounterweightShape read_shape(const MapReader::Entry& shape, const std::string& path) {
    const std::string t = read_text(r_, shape, path + ".shape");
    if (t != "point" && t != "disc") {
      r_.fail(mark_of(shape.value, shape.key_mark),
              path + ".shape must be point or disc, got " + describe(shape.value));
    }
    return t == "disc" ? balance::CounterweightShape::kDisc : balance::CounterweightShape::kPoint;
  }

  balance::CounterweightSpec read_counterweight(const MapReader::Entry& e,
                                                const std::string& path) {
    balance::CounterweightSpec spec;
    if (e.value.IsNull()) return spec;
    const MapReader m(r_, e.value, path, e.key_mark,
                      "(shape, mass, distance, radius, thickness, density)");
    m.check_keys({"shape", "mass", "distance", "radius", "thickness", "density"});
    if (const MapReader::Entry* shape = m.find("shape")) spec.shape = read_shape(*shape, path);
    const bool disc = spec.shape == balance::CounterweightShape::kDisc;
    auto positive = [&](const MapReader::Entry& x, const char* unit) {
      const double v = read_number(r_, x, path + "." + x.key, unit);
      if (!(v > 0)) {
        r_.fail(mark_of(x.value, x.key_mark),
                path + "." + x.key + " must be > 0 " + unit + ", got " + text::exact(v));
      }
      return v;
    };
    // a disc's size: only for shape: disc
    for (const char* key : {"radius", "thickness", "density"}) {
      const MapReader::Entry* x = m.find(key);
      if (x && !disc) {
        r_.fail(x->key_mark, path + "." + key + " needs shape: disc (a point mass has no size)");
      }
    }
    // at most one of mass, distance, radius is given; the rest is solved
    const MapReader::Entry* given = nullptr;
    for (const char* key : {"mass", "distance", "radius"}) {
      const MapReader::Entry* x = m.find(key);
      if (!x) continue;
      if (given) {
        const MapReader::Entry* later = given->key_mark.pos > x->key_mark.pos ? given : x;
        r_.fail(later->key_mark, path +
                                     ": give at most one of mass, distance and radius (the "
                                     "rest is solved), got both " +
                                     given->key + " and " + x->key);
      }
      given = x;
    }
    if (const MapReader::Entry* x = m.find("mass")) spec.mass = positive(*x, "kg");
    if (const MapReader::Entry* x = m.find("distance")) spec.distance = positive(*x, "m");
    if (const MapReader::Entry* x = m.find("radius")) spec.radius = positive(*x, "m");
    if (const MapReader::Entry* x = m.find("thickness")) spec.thickness = positive(*x, "m");
    if (const MapReader::Entry* x = m.find("density")) spec.density = positive(*x, "kg/m^3");
    // anything else the balance layer objects to, at the side's key
    if (const auto problem = spec.validate()) r_.fail(e.key_mark, path + ": " + problem->text());
    return spec;
  }

  // balance.counter_rotations: {crank: {at}, rocker: {at}}
  void read_shafts(const MapReader::Entry& e, double frame, balance::BalanceRequest& request) {
    if (e.value.IsNull()) return;
    const MapReader cr(r_, e.value, "balance.counter_rotations", e.key_mark, "(crank, rocker)");
    cr.check_keys({"crank", "rocker"});
    std::optional<Vec2>* targets[] = {&request.crank_at, &request.rocker_at};
    for (int i = 0; i < 2; ++i) {
      const std::string side = kSides[i];
      const MapReader::Entry* x = cr.find(side);
      if (!x) continue;
      const std::string path = "balance.counter_rotations." + side;
      const MapReader m(r_, x->value, path, x->key_mark, "(at)");
      m.check_keys({"at"});
      const MapReader::Entry& at = m.require("at", "the shaft position [x, y] on the frame in m");
      *targets[i] = read_shaft(at, path + ".at", i, frame);
    }
  }

  // ---- optimize ----

  // "Fsh_rms, Fsh_max, ..., added_mass"
  static std::string metric_names() {
    std::vector<std::string> names;
    for (optimize::Metric m : optimize::kMetrics) names.emplace_back(optimize::to_string(m));
    return join(names);
  }

  // a metric named by a key or a value; `where` names the map or key in the message
  optimize::Metric read_metric(const std::string& name, const YAML::Mark& mark,
                               const std::string& where) {
    if (const auto m = optimize::metric_named(name)) return *m;
    r_.fail(mark,
            "unknown metric '" + name + "' in " + where + "; expected one of " + metric_names());
  }

  // a metric that is zero in every free scene cannot be normalised by the original's value
  void check_metric_in_scene(optimize::Metric m, const Scene& scene, const YAML::Mark& mark,
                             const std::string& path) {
    const bool tau = m == optimize::Metric::kTauRms || m == optimize::Metric::kTauMax;
    if (tau && std::holds_alternative<core::FreeScene>(scene)) {
      r_.fail(mark, path +
                        ": a free scene has no drive torque (tau is 0 throughout), so there is "
                        "nothing to minimise or bound; use a driven scene");
    }
  }

  // optimize: {algorithm, objective, constraints, variables, max_evaluations, tolerance, pareto}
  OptimizeRequest read_optimize(const MapReader::Entry& e, const Study& study) {
    OptimizeRequest req;
    const MapReader o(r_, e.value, "optimize", e.key_mark,
                      "(algorithm, objective, constraints, variables, max_evaluations, tolerance, "
                      "pareto)");
    o.check_keys({"algorithm", "objective", "constraints", "variables", "max_evaluations",
                  "tolerance", "pareto"});

    YAML::Mark algorithm_mark = e.key_mark, evaluations_mark = e.key_mark,
               tolerance_mark = e.key_mark;
    if (const MapReader::Entry* a = o.find("algorithm")) {
      const std::string name = read_text(r_, *a, "optimize.algorithm");
      algorithm_mark = mark_of(a->value, a->key_mark);
      const auto alg = optimize::algorithm_named(name);
      if (!alg) {
        std::vector<std::string> all;
        for (optimize::Algorithm x : kAlgorithms) all.emplace_back(optimize::to_string(x));
        r_.fail(algorithm_mark, "unknown algorithm '" + name +
                                    "' in optimize.algorithm; expected one of " + join(all));
      }
      req.options.algorithm = *alg;
    }
    read_objective(o.require("objective", "the metrics to minimise, each with a weight"), study,
                   req);
    if (const MapReader::Entry* c = o.find("constraints")) read_constraints(*c, study, req);
    read_variables(o.require("variables",
                             "what may change: counterweights on crank and rocker, links' "
                             "mass parameters"),
                   study.model, req);
    if (const MapReader::Entry* n = o.find("max_evaluations")) {
      req.options.max_evaluations = read_count(r_, *n, "optimize.max_evaluations", 1, 1e9);
      evaluations_mark = mark_of(n->value, n->key_mark);
    }
    if (const MapReader::Entry* t = o.find("tolerance")) {
      const double tol = read_number(r_, *t, "optimize.tolerance", "");
      tolerance_mark = mark_of(t->value, t->key_mark);
      if (!(tol > 0 && tol < 1)) {
        r_.fail(tolerance_mark,
                "optimize.tolerance must be > 0 and < 1 (relative, on the variables and the "
                "objective), got " +
                    text::exact(tol));
      }
      req.options.relative_tolerance = tol;
    }
    if (const MapReader::Entry* p = o.find("pareto")) req.pareto = read_pareto(*p, study.scene);

    // the optimize layer's own checks of the whole problem and of the options, at the section
    Study with = study;
    with.optimize = req;
    const optimize::DesignProblem problem = design_problem(with);
    if (const Problem p = problem.validate()) r_.fail(e.key_mark, "optimize: " + p->text());
    if (const Problem p = req.options.validate()) {
      YAML::Mark where = e.key_mark;
      if (p->field == "max_evaluations") where = evaluations_mark;
      if (p->field == "relative_tolerance" || p->field == "constraint_tolerance") {
        where = tolerance_mark;
      }
      if (p->field == "algorithm") where = algorithm_mark;
      r_.fail(where, "optimize: " + p->text());
    }
    check_evaluation(problem, req, e.key_mark);
    check_algorithm(problem, req, algorithm_mark);
    return req;
  }

  // the optimize layer sets up the problem as it will solve it: the original simulated in the
  // scene (its metrics are the normalisers, which must not vanish); its complaint is reported at
  // the objective term or constraint whose field it names, else at the section
  void check_evaluation(const optimize::DesignProblem& problem, const OptimizeRequest& req,
                        const YAML::Mark& section) {
    struct Named {
      YAML::Mark mark;
      std::string path;
    };
    std::vector<Named> terms, limits;
    for (std::size_t i = 0; i < problem.objective.size(); ++i) {
      terms.push_back({term_marks_[i], std::string("optimize.objective.") +
                                           optimize::to_string(problem.objective[i].metric)});
    }
    for (std::size_t i = 0; i < problem.limits.size(); ++i) {
      limits.push_back({limit_marks_[i], std::string("optimize.constraints.") +
                                             optimize::to_string(problem.limits[i].metric)});
    }
    auto set_up = [&](const optimize::DesignProblem& p, const std::vector<Named>& t,
                      const std::vector<Named>& l) {
      try {
        const optimize::Nlp nlp(p);
      } catch (const InputError& err) {
        if (const auto& f = err.field(); f && f->index >= 0) {
          const std::vector<Named>* named = f->field == "objective" ? &t
                                            : f->field == "limits"  ? &l
                                                                    : nullptr;
          const auto i = static_cast<std::size_t>(f->index);
          if (named && i < named->size()) r_.fail((*named)[i].mark, f->joined((*named)[i].path));
        }
        r_.fail(section, "optimize: " + std::string(err.what()));
      }
    };
    set_up(problem, terms, limits);
    // each point of a Pareto front minimises `first` with a bound on `second`
    if (req.pareto) {
      optimize::DesignProblem p = problem;
      p.objective = {optimize::Term{req.pareto->first, 1.0}};
      p.limits.push_back(optimize::Limit{req.pareto->second, 1.0});
      limits.push_back({pareto_marks_[1], "optimize.pareto.second"});
      set_up(p, {{pareto_marks_[0], "optimize.pareto.first"}}, limits);
    }
  }

  // a gradient method in a free scene (whose every evaluation is a simulation, without
  // derivatives) is reported at `algorithm` in optimize()'s own words (optimize() refuses what
  // check_algorithm() refuses). In a free scene that is its only complaint; in a driven scene
  // (mma with force_balance) the run reports it, as before.
  void check_algorithm(const optimize::DesignProblem& problem, const OptimizeRequest& req,
                       const YAML::Mark& algorithm_mark) {
    if (!std::holds_alternative<core::FreeScene>(problem.scene)) return;
    if (const Problem p = optimize::check_algorithm(problem, req.options)) {
      r_.fail(algorithm_mark, "optimize.algorithm: " + p->text());
    }
  }

  // optimize.objective: {metric: weight, ...}
  void read_objective(const MapReader::Entry& e, const Study& study, OptimizeRequest& req) {
    const MapReader m(r_, e.value, "optimize.objective", e.key_mark,
                      "of metric: weight (e.g. Msh_rms: 1.0)");
    bool positive = false;
    for (const MapReader::Entry& x : m.entries()) {
      const optimize::Metric metric = read_metric(x.key, x.key_mark, "optimize.objective");
      const std::string path = "optimize.objective." + x.key;
      check_metric_in_scene(metric, study.scene, x.key_mark, path);
      const double w = read_number(r_, x, path, "");
      if (w < 0) {
        r_.fail(mark_of(x.value, x.key_mark),
                path + " must be >= 0 (a weight), got " + text::exact(w));
      }
      positive = positive || w > 0;
      req.objective.push_back({metric, w});
      term_marks_.push_back(x.key_mark);
    }
    if (!positive) {
      r_.fail(e.key_mark, "optimize.objective needs at least one metric with a weight > 0");
    }
  }

  // optimize.constraints: {force_balance: bool, metric: fraction, added_mass: kg}
  void read_constraints(const MapReader::Entry& e, const Study& study, OptimizeRequest& req) {
    if (e.value.IsNull()) return;  // `constraints:` with nothing under it: none
    const MapReader m(r_, e.value, "optimize.constraints", e.key_mark,
                      "(force_balance, and metric: bound)");
    for (const MapReader::Entry& x : m.entries()) {
      const std::string path = "optimize.constraints." + x.key;
      const YAML::Mark vm = mark_of(x.value, x.key_mark);
      if (x.key == "force_balance") {
        bool b = false;
        if (!x.value.IsScalar() || !YAML::convert<bool>::decode(x.value, b)) {
          r_.fail(vm, path + " must be true or false, got " + describe(x.value));
        }
        req.force_balance = b;
        continue;
      }
      if (!optimize::metric_named(x.key)) {
        r_.fail(x.key_mark, "unknown constraint '" + x.key +
                                "' in optimize.constraints; expected force_balance or one of " +
                                metric_names());
      }
      const optimize::Metric metric = *optimize::metric_named(x.key);
      check_metric_in_scene(metric, study.scene, x.key_mark, path);
      if (metric == optimize::Metric::kAddedMass) {
        // may be 0 or negative: keep the mass as it is, or take some away
        req.limits.push_back({metric, read_number(r_, x, path, "kg")});
        limit_marks_.push_back(x.key_mark);
      } else {
        const double v = read_number(r_, x, path, "");
        if (!(v > 0)) {
          r_.fail(vm, path + " must be > 0 (a fraction of the original design's value), got " +
                          text::exact(v));
        }
        req.limits.push_back({metric, v});
        limit_marks_.push_back(x.key_mark);
      }
    }
  }

  // optimize.variables: {counterweights: {crank, rocker}, links: {crank, coupler, rocker}}
  void read_variables(const MapReader::Entry& e, const core::FourBar& model, OptimizeRequest& req) {
    const MapReader v(r_, e.value, "optimize.variables", e.key_mark, "(counterweights, links)");
    v.check_keys({"counterweights", "links"});
    if (const MapReader::Entry* cw = v.find("counterweights"); cw && !cw->value.IsNull()) {
      const MapReader sides(r_, cw->value, "optimize.variables.counterweights", cw->key_mark,
                            "(crank, rocker)");
      sides.check_keys({"crank", "rocker"});
      for (int i = 0; i < 2; ++i) {
        if (const MapReader::Entry* x = sides.find(kSides[i])) {
          const int link = i == 0 ? 1 : 3;
          req.counterweights.push_back(read_counterweight_variables(
              *x, "optimize.variables.counterweights." + std::string(kSides[i]), link,
              core::link(model, link).length));
        }
      }
    }
    if (const MapReader::Entry* links = v.find("links"); links && !links->value.IsNull()) {
      const MapReader lk(r_, links->value, "optimize.variables.links", links->key_mark,
                         "(crank, coupler, rocker)");
      lk.check_keys({"crank", "coupler", "rocker"});
      for (const MapReader::Entry& x : lk.entries()) {
        const int link = x.key == "crank" ? 1 : x.key == "coupler" ? 2 : 3;
        read_link_parameters(x, "optimize.variables.links." + x.key, link, req);
      }
    }
    if (req.counterweights.empty() && req.link_parameters.empty()) {
      r_.fail(e.key_mark,
              "optimize.variables: no design variable; give counterweights (crank, rocker) or "
              "links (mass, e, f, inertia within bounds)");
    }
  }

  // {mass_max, distance_max, shape, thickness, density}
  optimize::CounterweightVariables read_counterweight_variables(const MapReader::Entry& e,
                                                                const std::string& path, int link,
                                                                double length) {
    optimize::CounterweightVariables cw;
    cw.link = link;
    cw.distance_max = length;  // default: the envelope of the link itself
    if (e.value.IsNull()) return cw;
    const MapReader m(r_, e.value, path, e.key_mark,
                      "(mass_max, distance_max, shape, thickness, density)");
    m.check_keys({"mass_max", "distance_max", "shape", "thickness", "density"});
    if (const MapReader::Entry* shape = m.find("shape")) cw.shape = read_shape(*shape, path);
    for (const char* key : {"thickness", "density"}) {
      const MapReader::Entry* x = m.find(key);
      if (x && cw.shape != balance::CounterweightShape::kDisc) {
        r_.fail(x->key_mark, path + "." + key + " needs shape: disc (a point mass has no size)");
      }
    }
    auto positive = [&](const MapReader::Entry& x, const char* unit) {
      const double v = read_number(r_, x, path + "." + x.key, unit);
      if (!(v > 0)) {
        r_.fail(mark_of(x.value, x.key_mark),
                path + "." + x.key + " must be > 0 " + unit + ", got " + text::exact(v));
      }
      return v;
    };
    if (const MapReader::Entry* x = m.find("mass_max")) cw.mass_max = positive(*x, "kg");
    if (const MapReader::Entry* x = m.find("distance_max")) cw.distance_max = positive(*x, "m");
    if (const MapReader::Entry* x = m.find("thickness")) cw.thickness = positive(*x, "m");
    if (const MapReader::Entry* x = m.find("density")) cw.density = positive(*x, "kg/m^3");
    return cw;
  }

  // {mass: [lo, hi], e: [lo, hi], f: [lo, hi], inertia: [lo, hi]}, at least one
  void read_link_parameters(const MapReader::Entry& e, const std::string& path, int link,
                            OptimizeRequest& req) {
    using P = optimize::LinkParameterVariable::Parameter;
    const MapReader m(r_, e.value, path, e.key_mark, "(mass, e, f, inertia, each [lower, upper])");
    m.check_keys({"mass", "e", "f", "inertia"});
    if (m.entries().empty()) {
      r_.fail(e.key_mark, path + ": give at least one of mass, e, f, inertia as [lower, upper]");
    }
    for (const MapReader::Entry& x : m.entries()) {
      const P p = x.key == "mass" ? P::kMass
                  : x.key == "e"  ? P::kE
                  : x.key == "f"  ? P::kF
                                  : P::kInertia;
      const char* unit = p == P::kMass ? "kg" : p == P::kInertia ? "kg m^2" : "m";
      const std::string xp = path + "." + x.key;
      const YAML::Mark vm = mark_of(x.value, x.key_mark);
      if (!x.value.IsSequence() || x.value.size() != 2) {
        r_.fail(vm, xp + " must be a list of 2 numbers [lower, upper] in " + unit + ", got " +
                        (x.value.IsSequence() ? "a list of " + std::to_string(x.value.size())
                                              : describe(x.value)));
      }
      const double lo = read_number(r_, x.value[0], vm, xp + "[0]", unit);
      const double hi = read_number(r_, x.value[1], vm, xp + "[1]", unit);
      if (!(lo < hi)) {
        r_.fail(vm, xp + " must have lower < upper, got [" + text::exact(lo) + ", " +
                        text::exact(hi) + "]");
      }
      if (p == P::kMass && !(lo > 0)) {
        r_.fail(mark_of(x.value[0], vm),
                xp + " lower bound must be > 0 kg (a link has mass), got " + text::exact(lo));
      }
      if (p == P::kInertia && lo < 0) {
        r_.fail(mark_of(x.value[0], vm),
                xp + " lower bound must be >= 0 kg m^2, got " + text::exact(lo));
      }
      optimize::LinkParameterVariable v;
      v.link = link;
      v.parameter = p;
      v.lower = lo;
      v.upper = hi;
      req.link_parameters.push_back(v);
    }
  }

  // optimize.pareto: {first, second, points}
  ParetoRequest read_pareto(const MapReader::Entry& e, const Scene& scene) {
    ParetoRequest p;
    const MapReader m(r_, e.value, "optimize.pareto", e.key_mark, "(first, second, points)");
    m.check_keys({"first", "second", "points"});
    const MapReader::Entry& first = m.require("first", "the metric minimised along the front");
    const MapReader::Entry& second = m.require("second", "the metric bounded along the front");
    const YAML::Mark fm = mark_of(first.value, first.key_mark);
    const YAML::Mark sm = mark_of(second.value, second.key_mark);
    p.first =
        read_metric(read_text(r_, first, "optimize.pareto.first"), fm, "optimize.pareto.first");
    check_metric_in_scene(p.first, scene, fm, "optimize.pareto.first");
    p.second =
        read_metric(read_text(r_, second, "optimize.pareto.second"), sm, "optimize.pareto.second");
    check_metric_in_scene(p.second, scene, sm, "optimize.pareto.second");
    pareto_marks_[0] = fm;
    pareto_marks_[1] = sm;
    if (p.first == p.second) {
      r_.fail(sm, std::string("optimize.pareto.second must differ from first (both are ") +
                      optimize::to_string(p.first) + ")");
    }
    if (const MapReader::Entry* n = m.find("points")) {
      p.points = read_count(r_, *n, "optimize.pareto.points", 2, 1000);
    }
    return p;
  }

  // ---- sweep ----

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
        r_.fail(list.key_mark, "sweep: the grid has " + product + " = " + text::exact(n) +
                                   " points, more than the " + text::exact(kMaxSweepPoints) +
                                   " a sweep may have");
      }
      req.points = static_cast<int>(n);
    }
    return req;
  }

  // sweep.seed: a whole number that reads back exactly
  std::uint64_t read_seed(const MapReader::Entry& e) {
    const double v = read_number(r_, e, "sweep.seed", "");
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
    p.from = read_number(r_, from, where + ".from", "");
    p.to = read_number(r_, to, where + ".to", "");
    if (!(p.from < p.to)) {
      r_.fail(mark_of(to.value, to.key_mark),
              where + ": from must be < to, got from = " + text::exact(p.from) +
                  ", to = " + text::exact(p.to));
    }
    if (p.log_scale && !(p.from > 0)) {
      r_.fail(mark_of(from.value, from.key_mark),
              where + ".from must be > 0 with scale: log, got " + text::exact(p.from));
    }
    if (design == SweepDesign::kGrid) {
      const int n = read_count(r_, *count, where + ".count", 2, kMaxSweepPoints);
      p.values = spaced_values(p.from, p.to, n, p.log_scale);
      for (std::size_t k = 1; k < p.values.size(); ++k) {
        if (p.values[k] > p.values[k - 1]) continue;
        r_.fail(mark_of(count->value, count->key_mark),
                where + ".count: " + std::to_string(n) + " values from " + text::exact(p.from) +
                    " to " + text::exact(p.to) +
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
      const double v = read_number(r_, item, vm, ip, "");
      if (log_scale && !(v > 0)) {
        r_.fail(mark_of(item, vm), ip + " must be > 0 with scale: log, got " + text::exact(v));
      }
      for (std::size_t j = 0; j < values.size(); ++j) {
        if (values[j] != v) continue;
        r_.fail(mark_of(item, vm), ip + " repeats values[" + std::to_string(j) + "] (" +
                                       text::exact(v) + "); a grid's values must be distinct");
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
    // where it leads: a number the study states
    double v = 0.0;
    if (node.IsScalar() && YAML::convert<double>::decode(node, v) && std::isfinite(v)) {
      return node;
    }
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

  core::Link read_link(const MapReader& lk, const std::string& name) {
    const std::string path = "linkage." + name;
    const MapReader::Entry& e =
        lk.require(name, "its length, mass, centre of mass (s, sigma or e, f) and inertia");
    const MapReader m(r_, e.value, path, e.key_mark,
                      "(length, mass, s and sigma or e and f, inertia)");
    m.check_keys({"length", "mass", "s", "sigma", "e", "f", "inertia"});

    auto number = [&](const MapReader::Entry& x, const char* unit) {
      const double v = read_number(r_, x, path + "." + x.key, unit);
      places_.push_back({name + "." + x.key, path + "." + x.key, mark_of(x.value, x.key_mark)});
      return v;
    };
    const double length = number(m.require("length", "l in m"), "m");
    const double mass = number(m.require("mass", "in kg"), "kg");

    // centre of mass: exactly one complete pair, {s, sigma} or {e, f}
    const MapReader::Entry* s = m.find("s");
    const MapReader::Entry* sigma = m.find("sigma");
    const MapReader::Entry* ce = m.find("e");
    const MapReader::Entry* cf = m.find("f");
    const MapReader::Entry* polar_first = first_of(s, sigma);
    const MapReader::Entry* cart_first = first_of(ce, cf);
    if (polar_first && cart_first) {
      const MapReader::Entry* later =
          polar_first->key_mark.pos > cart_first->key_mark.pos ? polar_first : cart_first;
      r_.fail(later->key_mark, path +
                                   " gives its centre of mass both as {s, sigma} and as "
                                   "{e, f}; give one pair only");
    }
    if (!polar_first && !cart_first) {
      r_.fail(e.key_mark, path +
                              ": missing the centre of mass; give s [m] and sigma [rad], "
                              "or e [m] and f [m]");
    }
    auto pair_check = [&](const MapReader::Entry* a, const MapReader::Entry* b, const char* an,
                          const char* bn) {
      if (a && !b) {
        r_.fail(a->key_mark,
                path + "." + an + " is given without " + bn + "; give both " + an + " and " + bn);
      }
    };
    pair_check(s, sigma, "s", "sigma");
    pair_check(sigma, s, "sigma", "s");
    pair_check(ce, cf, "e", "f");
    pair_check(cf, ce, "f", "e");

    const double inertia =
        number(m.require("inertia", "I about the centre of mass in kg m^2"), "kg m^2");
    if (s) {
      const double sv = number(*s, "m");
      if (sv < 0) {
        r_.fail(mark_of(s->value, s->key_mark), path +
                                                    ".s must be >= 0 m (sigma gives the "
                                                    "direction), got " +
                                                    text::exact(sv));
      }
      const double sg = number(*sigma, "rad");
      return core::link_from_polar(length, mass, sv, sg, inertia);
    }
    core::Link link;
    link.length = length;
    link.mass = mass;
    link.e = number(*ce, "m");
    link.f = number(*cf, "m");
    link.inertia = inertia;
    return link;
  }

  static const MapReader::Entry* first_of(const MapReader::Entry* a, const MapReader::Entry* b) {
    if (!a) return b;
    if (!b) return a;
    return a->key_mark.pos <= b->key_mark.pos ? a : b;
  }

  core::Loads read_loads(const MapReader::Entry& e) {
    core::Loads loads;
    if (e.value.IsNull()) return loads;  // `loads:` with nothing under it: all zero
    const MapReader ld(r_, e.value, "loads", e.key_mark, "(gravity, crank, coupler, rocker)");
    ld.check_keys({"gravity", "crank", "coupler", "rocker"});
    if (const MapReader::Entry* g = ld.find("gravity")) {
      YAML::Mark marks[2];
      loads.gravity = read_vec2(r_, *g, "loads.gravity", "m/s^2", marks);
      places_.push_back({"loads.gravity[0]", "loads.gravity[0]", marks[0]});
      places_.push_back({"loads.gravity[1]", "loads.gravity[1]", marks[1]});
    }
    const char* names[] = {"crank", "coupler", "rocker"};
    core::LinkLoad* targets[] = {&loads.crank, &loads.coupler, &loads.rocker};
    for (int k = 0; k < 3; ++k) {
      const MapReader::Entry* l = ld.find(names[k]);
      if (!l || l->value.IsNull()) continue;
      const std::string path = std::string("loads.") + names[k];
      const MapReader lm(r_, l->value, path, l->key_mark, "(force, moment)");
      lm.check_keys({"force", "moment"});
      if (const MapReader::Entry* f = lm.find("force")) {
        YAML::Mark marks[2];
        targets[k]->force = read_vec2(r_, *f, path + ".force", "N", marks);
        places_.push_back({path + ".force[0]", path + ".force[0]", marks[0]});
        places_.push_back({path + ".force[1]", path + ".force[1]", marks[1]});
      }
      if (const MapReader::Entry* mo = lm.find("moment")) {
        targets[k]->moment = read_number(r_, *mo, path + ".moment", "N m");
        places_.push_back({path + ".moment", path + ".moment", mark_of(mo->value, mo->key_mark)});
      }
    }
    return loads;
  }

  // core::make_fourbar() checks the physics; its complaint is reported where the value is
  core::FourBar checked_model(const core::FourBar& model, const YAML::Mark& linkage_mark) {
    try {
      return core::make_fourbar(model);
    } catch (const InputError& err) {
      const std::string msg = err.what();
      const Place* best = nullptr;
      for (const Place& p : places_) {
        const bool prefix = msg.compare(0, p.core_name.size(), p.core_name) == 0 &&
                            (msg.size() == p.core_name.size() || msg[p.core_name.size()] == ' ');
        if (prefix && (!best || p.core_name.size() > best->core_name.size())) best = &p;
      }
      if (best) r_.fail(best->mark, best->study_path + msg.substr(best->core_name.size()));
      r_.fail(linkage_mark, msg);
    }
  }

  Scene read_scene(const MapReader::Entry& e) {
    const MapReader sc(r_, e.value, "scene", e.key_mark,
                       "(type, theta1, omega1, duration or revolutions, samples)");
    const MapReader::Entry& type = sc.require("type", "free or driven");
    const std::string t = read_text(r_, type, "scene.type");
    const YAML::Mark tm = mark_of(type.value, type.key_mark);
    auto get = [&](const std::string& key, double fallback, const char* unit) {
      const MapReader::Entry* x = sc.find(key);
      return x ? read_number(r_, *x, "scene." + key, unit) : fallback;
    };

    if (t == "free") {
      sc.check_keys({"type", "theta1", "omega1", "duration", "samples"}, " in scene (type: free)");
      core::FreeScene free;
      free.theta1 = get("theta1", 0.0, "rad");
      note_theta1(sc);
      free.omega1 = get("omega1", 0.0, "rad/s");
      const MapReader::Entry& d = sc.require("duration", "the simulated time in s");
      free.duration = read_number(r_, d, "scene.duration", "s");
      if (free.duration <= 0) {
        r_.fail(mark_of(d.value, d.key_mark),
                "scene.duration must be > 0 s, got " + text::exact(free.duration));
      }
      if (const MapReader::Entry* n = sc.find("samples")) {
        free.samples = read_count(r_, *n, "scene.samples", 2, kMaxRows);
      }
      return free;
    }
    if (t == "driven") {
      sc.check_keys({"type", "theta1", "omega1", "revolutions", "samples"},
                    " in scene (type: driven)");
      core::DrivenScene driven;
      driven.theta1 = get("theta1", 0.0, "rad");
      note_theta1(sc);
      const MapReader::Entry& w = sc.require("omega1", "the constant crank speed in rad/s");
      driven.omega1 = read_number(r_, w, "scene.omega1", "rad/s");
      if (driven.omega1 == 0) {
        r_.fail(mark_of(w.value, w.key_mark),
                "scene.omega1 must be != 0 rad/s in a driven scene (the constant crank speed)");
      }
      if (const MapReader::Entry* n = sc.find("revolutions")) {
        driven.revolutions = read_count(r_, *n, "scene.revolutions", 1, kMaxRows);
      }
      if (const MapReader::Entry* n = sc.find("samples")) {
        driven.samples = read_count(r_, *n, "scene.samples", 1, kMaxRows);
      }
      if (static_cast<double>(driven.samples) * driven.revolutions > kMaxRows) {
        r_.fail(e.key_mark,
                "scene.samples x scene.revolutions must be <= " + text::exact(kMaxRows) +
                    " rows, got " +
                    text::exact(static_cast<double>(driven.samples) * driven.revolutions));
      }
      return driven;
    }
    r_.fail(tm, "scene.type must be free or driven, got " + describe(type.value));
  }

  void note_theta1(const MapReader& sc) {
    if (const MapReader::Entry* x = sc.find("theta1")) {
      scene_places_.push_back({"theta1", "scene.theta1", mark_of(x->value, x->key_mark)});
    }
  }

  void check_assembly(const core::FourBar& model, const Scene& scene,
                      const YAML::Mark& scene_mark) {
    const double theta1 = std::visit([](const auto& s) { return s.theta1; }, scene);
    const auto pose = core::solve_position(model, theta1);
    if (pose) return;
    // report at scene.theta1 when given, else at the scene (theta1 defaulted to 0)
    YAML::Mark where = scene_mark;
    for (const Place& p : scene_places_) where = p.mark;
    r_.fail(where,
            "the linkage cannot be assembled at the initial crank angle: " + pose.error().what());
  }

  std::optional<core::Formulation> read_method(const MapReader::Entry& e) {
    const std::string name = read_text(r_, e, "method");
    if (name == "auto") return std::nullopt;
    if (const auto f = formulation_named(name)) return f;
    std::vector<std::string> all(std::begin(kMethodNames), std::end(kMethodNames));
    r_.fail(mark_of(e.value, e.key_mark),
            "unknown method '" + name + "'; expected one of " + join(all));
    return std::nullopt;
  }

  double read_tolerance(const MapReader::Entry& e) {
    const double tol = read_number(r_, e, "tolerance", "");
    const YAML::Mark m = mark_of(e.value, e.key_mark);
    if (!(tol > 0 && tol < 1)) {
      r_.fail(m, "tolerance must be > 0 and < 1 (a relative tolerance), got " + text::exact(tol));
    }
    core::SimulateOptions options;
    options.tolerance = tol;
    if (const auto problem = options.validate()) r_.fail(m, "tolerance: " + problem->text());
    return tol;
  }

  const Reporter& r_;
  std::vector<Place> places_;            // linkage and loads values, for make_fourbar()'s messages
  std::vector<Place> scene_places_;      // scene.theta1 when given
  std::vector<YAML::Mark> term_marks_;   // optimize.objective's keys, one per term
  std::vector<YAML::Mark> limit_marks_;  // optimize.constraints' metric keys, one per limit
  YAML::Mark pareto_marks_[2];           // optimize.pareto.first and .second
};

}  // namespace

namespace internal {

Study parse_study_tree(const YAML::Node& root, const std::string& source_name) {
  const Reporter r(source_name);
  StudyParser parser(r);
  try {
    return parser.parse(root);
  } catch (const YAML::Exception& e) {
    // conversions are checked before use, so this is unexpected; still report it in place
    r.fail(e.mark, e.msg);
  }
}

std::optional<std::vector<PathStep>> parse_path(const std::string& path) {
  auto name_char = [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
           c == '-';
  };
  std::vector<PathStep> steps;
  std::size_t i = 0;
  const std::size_t n = path.size();
  while (true) {
    // a key, then any number of [index]
    const std::size_t start = i;
    while (i < n && name_char(path[i])) ++i;
    if (i == start) return std::nullopt;
    steps.push_back({path.substr(start, i - start), 0});
    while (i < n && path[i] == '[') {
      const std::size_t digits = ++i;
      while (i < n && path[i] >= '0' && path[i] <= '9') ++i;
      const std::size_t len = i - digits;
      // one canonical spelling per element (no leading zeros), and small enough to convert
      if (len == 0 || len > 9 || (len > 1 && path[digits] == '0')) return std::nullopt;
      if (i == n || path[i] != ']') return std::nullopt;
      steps.push_back({"", std::stoul(path.substr(digits, len))});
      ++i;
    }
    if (i == n) return steps;
    if (path[i] != '.') return std::nullopt;
    ++i;
  }
}

YAML::Node node_at(YAML::Node root, const std::vector<PathStep>& steps) {
  // Node::reset() rebinds; assigning a Node would overwrite the node it refers to
  YAML::Node node;
  node.reset(root);
  for (const PathStep& s : steps) {
    const YAML::Node next = s.key.empty() ? node[s.index] : node[s.key];
    node.reset(next);
  }
  return node;
}

}  // namespace internal

Study parse_study(const std::string& yaml_text, const std::string& source_name) {
  const Reporter r(source_name);
  std::vector<YAML::Node> docs;
  try {
    docs = YAML::LoadAll(yaml_text);
  } catch (const YAML::Exception& e) {
    r.fail(e.mark, e.msg);
  }
  if (docs.size() > 1) {
    r.fail(mark_of(docs[1], YAML::Mark()),
           "a study file holds one YAML document; found a second one (after '---')");
  }
  Study study = internal::parse_study_tree(docs.empty() ? YAML::Node() : docs[0], source_name);
  // each point of a sweep is this text with its values set (point_study())
  if (study.sweep) study.sweep->study_text = yaml_text;
  return study;
}

Study load_study(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    throw StudyError(path, 0, 0, "is a directory, not a study file");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw StudyError(path, 0, 0, "cannot open the study file");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw StudyError(path, 0, 0, "cannot read the study file");
  return parse_study(text.str(), path);
}

}  // namespace bd::studies
