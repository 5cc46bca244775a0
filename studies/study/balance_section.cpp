// The balance section: a four-bar's says what to balance and with what, synthesised at load time
// (balance/synthesis.hpp; a synthesis that is not possible is reported at the key asking); a
// planar linkage's names the links to carry counterweights, checked here and synthesised by the
// runner from the motion (balance/planar.hpp).
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "balance/planar_moment.hpp"
#include "balance/planar_shafts.hpp"
#include "studies/study/sections.hpp"
#include "studies/study/yaml_reader.hpp"

namespace bd::studies::detail {

balance::CounterweightShape read_shape(const Reporter& r_, const MapReader::Entry& shape,
                                       const std::string& path) {
  const std::string t = read_text(r_, shape, path + ".shape");
  if (t != "point" && t != "disc") {
    r_.fail(mark_of(shape.value, shape.key_mark),
            path + ".shape must be point or disc, got " + describe(shape.value));
  }
  return t == "disc" ? balance::CounterweightShape::kDisc : balance::CounterweightShape::kPoint;
}

balance::Counterweight read_counterweight_part(const Reporter& r_, const MapReader& m,
                                              const std::string& path) {
  balance::Counterweight cw;
  const MapReader::Entry& mass = m.require("mass", "in kg");
  cw.mass = read_number(r_, mass, path + ".mass", "kg");
  if (!(cw.mass >= 0)) {  // 0 kg leaves the link as it is (an optimum may place none)
    r_.fail(mark_of(mass.value, mass.key_mark),
            path + ".mass must be >= 0 kg, got " + text::shortest(cw.mass));
  }
  YAML::Mark marks[2];
  cw.position = read_vec2(
      r_, m.require("at", "its centre [x, y] in m, in the link's axes from the pivot"),
      path + ".at", "m", marks);
  cw.distance = cw.position.norm();
  if (const MapReader::Entry* j = m.find("inertia")) {
    cw.inertia = read_number(r_, *j, path + ".inertia", "kg m²");
    if (!(cw.inertia >= 0)) {
      r_.fail(mark_of(j->value, j->key_mark),
              path + ".inertia must be >= 0 kg m², got " + text::shortest(cw.inertia));
    }
  }
  return cw;
}

namespace {

class BalanceReader {
 public:
  explicit BalanceReader(const Reporter& r) : r_(r) {}

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
    } catch (const InputError& err) {
      // the balanced design checked as a linkage (a counterweight out of range): the run would
      // refuse it, so validation does
      r_.fail(force_mark, std::string("balance: the balanced design is not a valid linkage: ") +
                              err.what());
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
      return read_positive(r_, x, path + "." + x.key, unit);
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

  balance::CounterweightShape read_shape(const MapReader::Entry& shape, const std::string& path) {
    return detail::read_shape(r_, shape, path);
  }
  Vec2 read_shaft(const MapReader::Entry& at, const std::string& path, int side, double frame) {
    return detail::read_shaft(r_, at, path, side, frame);
  }

 private:
  const Reporter& r_;
};

// balance: {force, counterweights} of a planar linkage: which links carry counterweights, checked
// against the linkage; the synthesis waits for the run (its conditions come from the motion)
// shafts: {orders: [1, 2], at: [x, y], radius: r}
balance::planar::ShaftRequest read_shafts(const Reporter& r_, const MapReader::Entry& e) {
  balance::planar::ShaftRequest q;
  const MapReader m(r_, e.value, "balance.shafts", e.key_mark, "(orders, at, radius)");
  m.check_keys({"orders", "at", "radius"});
  const MapReader::Entry& o =
      m.require("orders", "the orders of the shaking force to cancel, e.g. [1, 2]");
  const YAML::Mark om = mark_of(o.value, o.key_mark);
  if (!o.value.IsSequence() || o.value.size() == 0) {
    r_.fail(om, "balance.shafts.orders must be a list of whole numbers >= 1, e.g. [1, 2], got " +
                    describe(o.value));
  }
  for (std::size_t i = 0; i < o.value.size(); ++i) {
    const std::string path = "balance.shafts.orders[" + std::to_string(i) + "]";
    const double n = read_number(r_, o.value[i], om, path, "");
    if (n != std::round(n) || n < 1 || n > 100) {
      r_.fail(mark_of(o.value[i], om),
              path + " must be a whole number from 1 to 100, got " + text::shortest(n));
    }
    for (std::size_t j = 0; j < q.orders.size(); ++j) {
      if (q.orders[j] == static_cast<int>(n)) {
        r_.fail(mark_of(o.value[i], om), path + " repeats order " + text::shortest(n) +
                                             " (orders[" + std::to_string(j) + "])");
      }
    }
    q.orders.push_back(static_cast<int>(n));
  }
  if (const MapReader::Entry* a = m.find("at")) {
    YAML::Mark marks[2];
    if (a->value.IsMap()) {
      // one place per shaft, by the name the synthesis gives it: shaft_<n>, shaft_-<n>
      const MapReader places(r_, a->value, "balance.shafts.at", a->key_mark,
                             "of shaft: [x, y] (e.g. shaft_2: [0, 0.1])");
      std::string names;
      for (int n : q.orders) {
        names += (names.empty() ? "" : ", ") + std::string("shaft_") + std::to_string(n) +
                 ", shaft_-" + std::to_string(n);
      }
      for (const MapReader::Entry& x : places.entries()) {
        const std::string path = "balance.shafts.at." + x.key;
        int ratio = 0;
        for (int n : q.orders) {
          if (x.key == "shaft_" + std::to_string(n)) ratio = n;
          if (x.key == "shaft_-" + std::to_string(n)) ratio = -n;
        }
        if (ratio == 0) {
          r_.fail(x.key_mark, path + ": no such shaft (the orders give " + names + ")");
        }
        q.at_shaft[ratio] = read_vec2(r_, x, path, "m", marks);
      }
    } else {
      q.at = read_vec2(r_, *a, "balance.shafts.at", "m", marks);
    }
  }
  if (const MapReader::Entry* x = m.find("radius")) {
    q.radius = read_number(r_, *x, "balance.shafts.radius", "m");
    if (!(*q.radius > 0)) {
      r_.fail(mark_of(x->value, x->key_mark),
              "balance.shafts.radius must be > 0 m, got " + text::shortest(*q.radius));
    }
  }
  return q;
}

// moment: full with counter_rotations: {<link>: {at: [x, y]}} (default: every link that turns
// about one ground node, shafts at their defaults)
std::vector<balance::planar::CounterRotationRequest> read_counter_rotations(
    const Reporter& r_, const MapReader::Entry& moment,
    const std::optional<MapReader::Entry>& rotations, const core::planar::Linkage& linkage) {
  namespace bp = balance::planar;
  std::vector<bp::CounterRotationRequest> out;
  std::map<int, YAML::Mark> marks;  // link -> where its counter-rotation is asked for
  if (rotations && !rotations->value.IsNull()) {
    const MapReader m(r_, rotations->value, "balance.counter_rotations", rotations->key_mark,
                      "(a link's name and its counter-rotation: {} or {at: [x, y]})");
    for (const MapReader::Entry& x : m.entries()) {
      const std::string path = "balance.counter_rotations." + x.key;
      const int link = core::planar::link_index(linkage, x.key);
      if (link < 0) r_.fail(x.key_mark, path + ": no link of that name");
      bp::CounterRotationRequest ask{link, std::nullopt};
      if (!x.value.IsNull()) {
        const MapReader at(r_, x.value, path, x.key_mark, "(at)");
        at.check_keys({"at"});
        if (const MapReader::Entry* a = at.find("at")) {
          YAML::Mark xy[2];
          ask.at = read_vec2(r_, *a, path + ".at", "m", xy);
        }
      }
      out.push_back(ask);
      marks[link] = x.key_mark;
    }
  } else {
    out = bp::default_counter_rotations(linkage);
    if (out.empty()) {
      r_.fail(mark_of(moment.value, moment.key_mark),
              "balance.moment: no link turns about a ground node to carry a counter-rotation");
    }
  }
  try {
    bp::check_counter_rotations(linkage, out);
  } catch (const InputError& err) {
    for (const auto& [link, mark] : marks) {
      const std::string field =
          "counter_rotations." + linkage.links[static_cast<std::size_t>(link)].name;
      if (err.field() && err.field()->field == field)
        r_.fail(mark, err.field()->joined("balance." + field));
    }
    r_.fail(mark_of(moment.value, moment.key_mark), std::string("balance.moment: ") + err.what());
  }
  return out;
}

balance::planar::BalanceRequest read_planar(const Reporter& r_, const MapReader::Entry& e,
                                            const core::planar::Linkage& linkage) {
  namespace bp = balance::planar;
  BalanceReader reader(r_);
  bp::BalanceRequest request;
  std::optional<MapReader::Entry> cw;  // a copy: the section's reader ends with its block
  std::optional<YAML::Mark> factor_mark, shafts_mark;
  std::optional<MapReader::Entry> moment, rotations;
  if (!e.value.IsNull()) {
    const MapReader b(r_, e.value, "balance", e.key_mark,
                      "(force, counterweights, balancing_factor, shafts, moment, "
                      "counter_rotations)");
    b.check_keys(
        {"force", "moment", "counterweights", "counter_rotations", "balancing_factor", "shafts"});
    if (const MapReader::Entry* f = b.find("force")) {
      if (!reader.read_full_or_none(*f, "balance.force")) {
        r_.fail(mark_of(f->value, f->key_mark),
                "balance.force: none leaves nothing to balance: a planar linkage is balanced "
                "from full force balance by counterweights");
      }
    }
    if (const MapReader::Entry* m = b.find("moment")) {
      if (reader.read_full_or_none(*m, "balance.moment")) moment = *m;
    }
    if (const MapReader::Entry* x = b.find("counter_rotations")) {
      if (!moment) {
        r_.fail(x->key_mark, "balance.counter_rotations are used only with balance.moment: full");
      }
      rotations = *x;
    }
    if (const MapReader::Entry* x = b.find("counterweights")) cw = *x;
    if (const MapReader::Entry* x = b.find("balancing_factor")) {
      request.balancing_factor = read_number(r_, *x, "balance.balancing_factor", "");
      factor_mark = mark_of(x->value, x->key_mark);
      if (!(*request.balancing_factor >= 0)) {
        r_.fail(*factor_mark,
                "balance.balancing_factor must be >= 0 (0.5 balances half the "
                "reciprocating mass), got " +
                    text::shortest(*request.balancing_factor));
      }
    }
    if (const MapReader::Entry* x = b.find("shafts")) {
      request.shafts = read_shafts(r_, *x);
      shafts_mark = x->key_mark;
    }
  }
  std::map<int, YAML::Mark> marks;  // link -> where its counterweight is asked for
  if (cw && !cw->value.IsNull()) {
    std::string names;
    for (const core::planar::Link& l : linkage.links) names += (names.empty() ? "" : ", ") + l.name;
    const MapReader m(r_, cw->value, "balance.counterweights", cw->key_mark,
                      "(a link's name and its counterweight: {} or shape, mass, distance, radius, "
                      "thickness, density)");
    for (const MapReader::Entry& x : m.entries()) {
      const int link = core::planar::link_index(linkage, x.key);
      if (link < 0) {
        r_.fail(x.key_mark, "balance.counterweights." + x.key +
                                ": no link of that name (links: " + names + ")");
      }
      request.counterweights.push_back(
          {link, reader.read_counterweight(x, "balance.counterweights." + x.key)});
      marks[link] = x.key_mark;
    }
  } else {
    request.counterweights = bp::grounded_links(linkage);
    if (request.counterweights.empty()) {
      r_.fail(cw ? cw->key_mark : e.key_mark,
              "balance: no link turns about a ground node to carry a counterweight by default; "
              "name the links to carry them in balance.counterweights (a floating link's "
              "counterweight needs its mass)");
    }
  }
  try {
    bp::check_counterweights(linkage, request.counterweights);
  } catch (const InputError& err) {
    // the field is counterweights.<link>[.<spec field>]: reported at the link's key
    for (const auto& [link, mark] : marks) {
      const std::string field =
          "counterweights." + linkage.links[static_cast<std::size_t>(link)].name;
      if (err.field() && err.field()->field.rfind(field, 0) == 0) {
        r_.fail(mark, err.field()->joined("balance." + err.field()->field));
      }
    }
    r_.fail(cw ? cw->key_mark : e.key_mark, std::string("balance: ") + err.what());
  }
  try {
    if (request.balancing_factor) {
      bp::check_balancing_factor(linkage, request.counterweights, *request.balancing_factor);
    }
  } catch (const InputError& err) {
    r_.fail(*factor_mark, err.field() ? err.field()->joined("balance.balancing_factor")
                                      : std::string("balance.balancing_factor: ") + err.what());
  }
  if (moment) request.counter_rotations = read_counter_rotations(r_, *moment, rotations, linkage);
  if (moment && request.balancing_factor) {
    r_.fail(mark_of(moment->value, moment->key_mark),
            "balance.moment: full needs full force balance, which a balancing factor does not "
            "give (it leaves part of the reciprocating mass)");
  }
  try {
    if (request.shafts) (void)bp::balance_shafts(linkage, *request.shafts);
  } catch (const InputError& err) {
    r_.fail(*shafts_mark, err.field() ? err.field()->joined("balance.shafts")
                                      : std::string("balance.shafts: ") + err.what());
  }
  return request;
}

}  // namespace

balance::planar::BalanceRequest read_planar_balance(const Reporter& r, const MapReader::Entry& e,
                                                    const core::planar::Linkage& linkage) {
  return read_planar(r, e, linkage);
}

balance::BalancedDesign read_balance(const Reporter& r, const MapReader::Entry& e,
                                     const core::FourBar& model) {
  return BalanceReader(r).read_balance(e, model);
}

}  // namespace bd::studies::detail
