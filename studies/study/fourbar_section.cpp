// The four-bar's sections of a study file: linkage (type: fourbar), loads and scene, checked by
// core::make_fourbar() and the closed-form assembly, each complaint at the value's place.
#include <fmt/printf.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "core/fourbar/kinematics.hpp"
#include "studies/study/sections.hpp"
#include "studies/study/yaml_reader.hpp"

namespace bd::studies::detail {

Vec2 read_shaft(const Reporter& r_, const MapReader::Entry& at, const std::string& path, int side,
                double frame) {
  YAML::Mark marks[2];
  const Vec2 p = read_vec2(r_, at, path, "m", marks);
  const Vec2 pivot = side == 0 ? Vec2(0, 0) : Vec2(frame, 0);
  if (p == pivot) {
    const std::string buf =
        fmt::sprintf("'s pivot %s = (%.10g, %.10g) m, got [%.10g, %.10g]", side == 0 ? "A0" : "A3",
                     pivot.x(), pivot.y(), p.x(), p.y());
    r_.fail(mark_of(at.value, at.key_mark), path + " must differ from the " + kSides[side] + buf);
  }
  return p;
}

namespace {

// where each quantity make_fourbar() may complain about sits in the file
struct Place {
  std::string core_name;   // the field make_fourbar() names ("coupler.mass", "loads.gravity[0]")
  std::string study_path;  // as the study file names it ("linkage.coupler.mass")
  YAML::Mark mark;
};

}  // namespace

class FourBarSection::Impl {
 public:
  explicit Impl(const Reporter& r) : r_(r) {}

  core::FourBar read_linkage(const MapReader::Entry& e) {
    const MapReader lk(r_, e.value, "linkage", e.key_mark,
                       "(type, frame, branch, crank, coupler, rocker)");
    lk.check_keys({"type", "frame", "branch", "crank", "coupler", "rocker", "counter_rotations",
                   "counterweights"});

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
    if (const MapReader::Entry* cw = lk.find("counterweights")) read_counterweights(*cw);
    return model;
  }

  // linkage.counterweights: {crank: {mass, at, inertia}, rocker: {...}}, each optional; `at`
  // in the link's axes from its pivot (A0 for the crank, A3 for the rocker)
  void read_counterweights(const MapReader::Entry& e) {
    if (e.value.IsNull()) return;
    const MapReader cw(r_, e.value, "linkage.counterweights", e.key_mark, "(crank, rocker)");
    cw.check_keys({"crank", "rocker"});
    for (int i = 0; i < 2; ++i) {
      const MapReader::Entry* x = cw.find(kSides[i]);
      if (!x) continue;
      const std::string path = "linkage.counterweights." + std::string(kSides[i]);
      const MapReader m(r_, x->value, path, x->key_mark, "(mass, at, inertia)");
      m.check_keys({"mass", "at", "inertia"});
      parts_.push_back({i == 0 ? 1 : 3, -1, read_counterweight_part(r_, m, path)});
    }
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
      const MapReader::Entry& j = m.require("inertia", "J of the disc about its shaft in kg m²");
      targets[i]->inertia = read_number(r_, j, path + ".inertia", "kg m²");
      places_.push_back({"counter_rotations." + side + ".inertia", path + ".inertia",
                         mark_of(j.value, j.key_mark)});
      const MapReader::Entry& at = m.require("at", "the shaft position [x, y] on the frame in m");
      targets[i]->at = read_shaft(at, path + ".at", i, frame);
    }
    return out;
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

    const CentreOfMassKeys com =
        centre_of_mass_keys(r_, m, e, path, "give s [m] and sigma [rad], or e [m] and f [m]");
    const double inertia =
        number(m.require("inertia", "I about the centre of mass in kg m²"), "kg m²");
    if (com.polar()) {
      const double sv = number(*com.s, "m");
      if (sv < 0) {
        r_.fail(mark_of(com.s->value, com.s->key_mark), path +
                                                            ".s must be >= 0 m (sigma gives the "
                                                            "direction), got " +
                                                            text::shortest(sv));
      }
      const double sg = number(*com.sigma, "rad");
      return core::link_from_polar(length, mass, sv, sg, inertia);
    }
    core::Link link;
    link.length = length;
    link.mass = mass;
    link.e = number(*com.e, "m");
    link.f = number(*com.f, "m");
    link.inertia = inertia;
    return link;
  }

  core::Loads read_loads(const MapReader::Entry& e) {
    core::Loads loads;
    if (e.value.IsNull()) return loads;  // `loads:` with nothing under it: all zero
    const MapReader ld(r_, e.value, "loads", e.key_mark, "(gravity, crank, coupler, rocker)");
    ld.check_keys({"gravity", "crank", "coupler", "rocker"});
    if (const MapReader::Entry* g = ld.find("gravity")) {
      YAML::Mark marks[2];
      loads.gravity = read_vec2(r_, *g, "loads.gravity", "m/s²", marks);
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
      // the field make_fourbar() names, with its element ("loads.gravity[0]"), is a place read
      if (const auto& f = err.field()) {
        const std::string key =
            f->field + (f->index >= 0 ? "[" + std::to_string(f->index) + "]" : "");
        for (const Place& p : places_) {
          if (p.core_name == key) r_.fail(p.mark, f->joined(p.study_path));
        }
      }
      r_.fail(linkage_mark, err.what());
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
                "scene.duration must be > 0 s, got " + text::shortest(free.duration));
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
                "scene.samples x scene.revolutions must be <= " + text::shortest(kMaxRows) +
                    " rows, got " +
                    text::shortest(static_cast<double>(driven.samples) * driven.revolutions));
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
    const double theta1 = crank_angle_at_start(scene);
    const auto pose = core::solve_position(model, theta1);
    if (pose) return;
    // report at scene.theta1 when given, else at the scene (theta1 defaulted to 0)
    YAML::Mark where = scene_mark;
    for (const Place& p : scene_places_) where = p.mark;
    r_.fail(where,
            "the linkage cannot be assembled at the initial crank angle: " + pose.error().what());
  }

  // a driven scene turns the crank through whole revolutions: refused at scene.type when the
  // loop cannot close at every crank angle (the run would stop at the first limit position)
  void check_turns(const core::FourBar& model, const Scene& scene, const MapReader::Entry& e) {
    if (!std::holds_alternative<core::DrivenScene>(scene)) return;
    const bool change_point = core::classify_grashof(model) == core::GrashofClass::kChangePoint;
    if (core::crank_turns_fully(model) && !change_point) return;
    const YAML::Node type = e.value["type"];
    const YAML::Mark where = type ? mark_of(type, e.key_mark) : e.key_mark;
    // the crank angles where the loop just closes: |A1 - A3| = l2 + l3 or |l2 - l3|
    const double l1 = model.crank.length, l4 = model.frame_length;
    std::string limits;
    for (double d : {model.coupler.length + model.rocker.length,
                     std::abs(model.coupler.length - model.rocker.length)}) {
      const double c = (l1 * l1 + l4 * l4 - d * d) / (2 * l1 * l4);
      if (std::abs(c) <= 1 + 1e-12) {
        const double a = std::acos(std::clamp(c, -1.0, 1.0));
        limits += std::string(limits.empty() ? "" : ", ") +
                  (a < 1e-9 || a > std::acos(-1.0) - 1e-9 ? "" : "±") + text::digits(a, 6);
      }
    }
    if (change_point) {
      // the crank turns, but where the links fold into one line the loop closes two ways
      r_.fail(where,
              "scene.type: driven turns the crank through whole revolutions, but this linkage is "
              "change-point (shortest + longest link = the other two): at theta1 = " +
                  limits +
                  " rad its links fold into one line, where it can go on as the linkage drawn "
                  "or as its crossed twin (a parallelogram as an antiparallelogram), and the "
                  "run cannot tell which; change a link length so that the sums differ");
      return;
    }
    r_.fail(where, std::string("scene.type: driven turns the crank through whole revolutions, but "
                               "this linkage is ") +
                       core::to_string(core::classify_grashof(model)) +
                       ": its loop cannot close at every crank angle" +
                       (limits.empty() ? "" : " (limit positions at theta1 = " + limits + " rad)") +
                       ", so the run would stop at the first limit position; simulate it with "
                       "type: free, which passes through them, or change the link lengths");
  }

  Vec2 read_shaft(const MapReader::Entry& at, const std::string& path, int side, double frame) {
    return detail::read_shaft(r_, at, path, side, frame);
  }

  const Reporter& r_;
  std::vector<Place> places_;        // linkage and loads values, for make_fourbar()'s messages
  std::vector<Place> scene_places_;  // scene.theta1 when given
 public:
  std::vector<CounterweightPart> parts_;  // linkage.counterweights, in file order
  std::optional<LinkageParts> parts;      // set by FourBarSection::read() when there are any
};

FourBarSection::FourBarSection(const Reporter& r) : impl_(std::make_unique<Impl>(r)) {}
FourBarSection::~FourBarSection() = default;

core::FourBar FourBarSection::read(const MapReader::Entry& linkage, const MapReader::Entry* loads) {
  core::FourBar model = impl_->read_linkage(linkage);
  if (loads) model.loads = impl_->read_loads(*loads);
  if (impl_->parts_.empty()) return impl_->checked_model(model, linkage.key_mark);
  // the links carry their counterweights: the model is the bare links with each merged in
  impl_->parts = LinkageParts{model, impl_->parts_};
  return impl_->checked_model(std::get<core::FourBar>(with_counterweights(*impl_->parts)),
                              linkage.key_mark);
}

std::optional<LinkageParts> FourBarSection::parts() const { return impl_->parts; }

Scene FourBarSection::read_scene(const MapReader::Entry& scene, const core::FourBar& model) {
  Scene s = impl_->read_scene(scene);
  impl_->check_assembly(model, s, scene.key_mark);
  impl_->check_turns(model, s, scene);
  return s;
}

}  // namespace bd::studies::detail
