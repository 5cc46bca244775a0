// A general planar linkage's sections of a study file (linkage type: planar):
//   linkage: {type: planar, nodes, links, point_masses, sliders, springs, balance_shafts, inputs}
//   loads:   {gravity, links: {<link>: {force, moment}}, nodes: {<node>: {force}}}
//   scene:   {type: driven, speeds, revolutions | duration, samples, start}
//            {type: free, rates, duration, samples, start}
// Names are the map keys; every reference to a node, link or slider is checked here, at its
// place, and what core::planar::make_linkage(), the mobility and the drawn closure say is
// reported at the place of the item whose field it names.
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "core/planar/dynamics.hpp"
#include "core/planar/simulate.hpp"
#include "studies/study/sections.hpp"
#include "studies/study/yaml_reader.hpp"

namespace bd::studies::detail {

namespace {
using core::planar::Input;
using core::planar::TimeFunction;
}  // namespace

class PlanarSection::Impl {
 public:
  explicit Impl(const Reporter& r) : r_(r) {}

  core::planar::Linkage read(const MapReader::Entry& e, const MapReader::Entry* loads) {
    const MapReader lk(r_, e.value, "linkage", e.key_mark,
                       "(type, nodes, links, point_masses, sliders, springs, balance_shafts, "
                       "inputs)");
    lk.check_keys({"type", "nodes", "links", "point_masses", "sliders", "springs", "balance_shafts",
                   "inputs", "counterweights"});
    linkage_mark_ = e.key_mark;
    core::planar::Linkage l;
    read_nodes(lk.require("nodes", "the joint points, each [x, y] in m or {at, ground}"), l);
    read_links(lk.require("links", "the rigid links, each through two or more nodes"), l);
    if (const MapReader::Entry* x = lk.find("point_masses")) read_point_masses(*x, l);
    if (const MapReader::Entry* x = lk.find("sliders")) read_sliders(*x, l);
    if (const MapReader::Entry* x = lk.find("springs")) read_springs(*x, l);
    if (const MapReader::Entry* x = lk.find("balance_shafts")) read_shafts(*x, l);
    const MapReader::Entry& inputs =
        lk.require("inputs", "the degrees of freedom: link angles or slider positions");
    read_inputs(inputs, l);
    if (loads) read_loads(*loads, l);
    if (const MapReader::Entry* x = lk.find("counterweights")) read_counterweights(*x, l);
    if (parts_.empty()) return checked(l, inputs);
    // the links carry their counterweights: the linkage is the bare links with each merged in
    parts = LinkageParts{l, parts_};
    return checked(std::get<core::planar::Linkage>(with_counterweights(*parts)), inputs);
  }

  // counterweights: {crank: {from: A0, mass, at: [x, y], inertia}, ...}: at most one per link,
  // `at` in the link's axes from `from` (default: its ground node, else its first node)
  void read_counterweights(const MapReader::Entry& e, const core::planar::Linkage& l) {
    if (e.value.IsNull()) return;
    const MapReader m(r_, e.value, "linkage.counterweights", e.key_mark,
                      "of link: {from, mass, at, inertia}");
    for (const MapReader::Entry& x : m.entries()) {
      const std::string path = "linkage.counterweights." + x.key;
      CounterweightPart part;
      part.link = link_named(YAML::Node(x.key), x.key_mark, "linkage.counterweights", l);
      const MapReader cm(r_, x.value, path, x.key_mark, "(from, mass, at, inertia)");
      cm.check_keys({"from", "mass", "at", "inertia"});
      const core::planar::Link& link = l.links[static_cast<std::size_t>(part.link)];
      part.pivot = balance::planar::counterweight_pivot(l, part.link);
      if (const MapReader::Entry* from = cm.find("from")) {
        part.pivot = node_named(from->value, from->key_mark, path + ".from", l);
        if (std::find(link.nodes.begin(), link.nodes.end(), part.pivot) == link.nodes.end()) {
          r_.fail(mark_of(from->value, from->key_mark),
                  path + ".from must be a node of link " + link.name + " (" +
                      nodes_text(l, link.nodes) + "), got " + from->value.Scalar());
        }
      }
      part.counterweight = read_counterweight_part(r_, cm, path);
      parts_.push_back(part);
    }
  }

  static std::string nodes_text(const core::planar::Linkage& l, const std::vector<int>& nodes) {
    std::string s;
    for (int n : nodes) s += (s.empty() ? "" : ", ") + l.nodes[static_cast<std::size_t>(n)].name;
    return s;
  }

  Scene read_scene(const MapReader::Entry& e, const core::planar::Linkage& l) {
    const MapReader sc(r_, e.value, "scene", e.key_mark,
                       "(type, speeds or rates, revolutions or duration, samples, start)");
    const MapReader::Entry& type = sc.require("type", "free or driven");
    const std::string t = read_text(r_, type, "scene.type");
    const std::size_t dof = l.inputs.size();
    if (t == "driven") {
      sc.check_keys({"type", "speeds", "revolutions", "duration", "samples", "start"},
                    " in scene (type: driven)");
      core::planar::DrivenScene d;
      d.speeds = read_values(sc.require("speeds", "the constant speed of each input, rad/s or m/s"),
                             "scene.speeds", dof, l, true);
      if (const MapReader::Entry* x = sc.find("start"))
        d.start = read_values(*x, "scene.start", dof, l, false);
      const MapReader::Entry* rev = sc.find("revolutions");
      const MapReader::Entry* dur = sc.find("duration");
      if (rev && dur) r_.fail(dur->key_mark, "scene: give revolutions or duration, not both");
      if (rev) d.revolutions = read_count(r_, *rev, "scene.revolutions", 1, kMaxRows);
      if (dur) d.duration = positive(*dur, "scene.duration", "s");
      if (const MapReader::Entry* n = sc.find("samples")) {
        d.samples = read_count(r_, *n, "scene.samples", dur ? 2 : 1, kMaxRows);
      }
      const core::planar::Model model(l);
      check_start(e, model, d.start);
      check_turns(e, type, model, d);
      return d;
    }
    if (t == "free") {
      sc.check_keys({"type", "rates", "duration", "samples", "start"}, " in scene (type: free)");
      core::planar::FreeScene f;
      if (const MapReader::Entry* x = sc.find("rates"))
        f.rates = read_values(*x, "scene.rates", dof, l, true);
      if (const MapReader::Entry* x = sc.find("start"))
        f.start = read_values(*x, "scene.start", dof, l, false);
      f.duration =
          positive(sc.require("duration", "the simulated time in s"), "scene.duration", "s");
      if (const MapReader::Entry* n = sc.find("samples")) {
        f.samples = read_count(r_, *n, "scene.samples", 2, kMaxRows);
      }
      check_start(e, core::planar::Model(l), f.start);
      return f;
    }
    r_.fail(mark_of(type.value, type.key_mark),
            "scene.type must be free or driven, got " + describe(type.value));
  }

 private:
  // ---- the linkage

  int node_named(const YAML::Node& v, const YAML::Mark& fallback, const std::string& path,
                 const core::planar::Linkage& l) {
    if (!v.IsScalar())
      r_.fail(mark_of(v, fallback), path + " must name a node, got " + describe(v));
    const int i = core::planar::node_index(l, v.Scalar());
    if (i < 0) {
      std::vector<std::string> names;
      for (const core::planar::Node& n : l.nodes) names.push_back(n.name);
      r_.fail(mark_of(v, fallback),
              path + ": unknown node '" + v.Scalar() + "'; the nodes are " + join(names));
    }
    return i;
  }

  int link_named(const YAML::Node& v, const YAML::Mark& fallback, const std::string& path,
                 const core::planar::Linkage& l) {
    if (!v.IsScalar())
      r_.fail(mark_of(v, fallback), path + " must name a link, got " + describe(v));
    const int i = core::planar::link_index(l, v.Scalar());
    if (i < 0) {
      std::vector<std::string> names;
      for (const core::planar::Link& k : l.links) names.push_back(k.name);
      r_.fail(mark_of(v, fallback),
              path + ": unknown link '" + v.Scalar() + "'; the links are " + join(names));
    }
    return i;
  }

  double positive(const MapReader::Entry& x, const std::string& path, const char* unit) {
    const double v = read_number(r_, x, path, unit);
    if (!(v > 0))
      r_.fail(mark_of(x.value, x.key_mark),
              path + " must be > 0 " + unit + ", got " + text::shortest(v));
    return v;
  }

  double non_negative(const MapReader::Entry& x, const std::string& path, const char* unit) {
    const double v = read_number(r_, x, path, unit);
    if (v < 0)
      r_.fail(mark_of(x.value, x.key_mark),
              path + " must be >= 0 " + unit + ", got " + text::shortest(v));
    return v;
  }

  // nodes: {A0: {at: [x, y], ground: true}, A1: [x, y], ...}
  void read_nodes(const MapReader::Entry& e, core::planar::Linkage& l) {
    const MapReader m(r_, e.value, "linkage.nodes", e.key_mark, "of name: [x, y] or {at, ground}");
    if (m.entries().empty()) r_.fail(e.key_mark, "linkage.nodes needs at least two nodes");
    for (const MapReader::Entry& x : m.entries()) {
      const std::string path = "linkage.nodes." + x.key;
      core::planar::Node n;
      n.name = x.key;
      YAML::Mark marks[2];
      if (x.value.IsMap()) {
        const MapReader nm(r_, x.value, path, x.key_mark, "(at, ground)");
        nm.check_keys({"at", "ground"});
        n.position =
            read_vec2(r_, nm.require("at", "the position [x, y] in m"), path + ".at", "m", marks);
        if (const MapReader::Entry* g = nm.find("ground"))
          n.ground = read_bool(r_, *g, path + ".ground");
      } else {
        n.position = read_vec2(r_, x, path, "m", marks);
      }
      places_["nodes[" + std::to_string(l.nodes.size()) + "]"] = {path, x.key_mark};
      l.nodes.push_back(n);
    }
  }

  // links: {crank: {nodes: [A0, A1], mass, e, f | s, sigma, inertia}, ...}
  void read_links(const MapReader::Entry& e, core::planar::Linkage& l) {
    const MapReader m(r_, e.value, "linkage.links", e.key_mark,
                      "of name: {nodes, mass, e and f or s and sigma, inertia}");
    if (m.entries().empty()) r_.fail(e.key_mark, "linkage.links needs at least one link");
    for (const MapReader::Entry& x : m.entries()) {
      const std::string path = "linkage.links." + x.key;
      const MapReader lm(r_, x.value, path, x.key_mark,
                         "(nodes, mass, s and sigma or e and f, inertia)");
      lm.check_keys({"nodes", "mass", "e", "f", "s", "sigma", "inertia"});
      core::planar::Link link;
      link.name = x.key;
      const MapReader::Entry& ne =
          lm.require("nodes", "the nodes it joins, its first two set its line");
      const YAML::Mark nm = mark_of(ne.value, ne.key_mark);
      if (!ne.value.IsSequence() || ne.value.size() < 2) {
        r_.fail(nm, path + ".nodes must be a list of two or more node names, got " +
                        describe(ne.value));
      }
      for (std::size_t i = 0; i < ne.value.size(); ++i) {
        const int n = node_named(ne.value[i], nm, path + ".nodes[" + std::to_string(i) + "]", l);
        if (std::find(link.nodes.begin(), link.nodes.end(), n) != link.nodes.end()) {
          r_.fail(mark_of(ne.value[i], nm),
                  path + ".nodes names " + ne.value[i].Scalar() + " twice");
        }
        link.nodes.push_back(n);
      }
      const core::planar::Node& p = l.nodes[static_cast<std::size_t>(link.nodes[0])];
      const core::planar::Node& q = l.nodes[static_cast<std::size_t>(link.nodes[1])];
      if (!((q.position - p.position).norm() > 0)) {
        r_.fail(nm, path + ": its first two nodes " + p.name + " and " + q.name +
                        " are drawn at the same point; they set the link's length and direction");
      }
      link.mass = non_negative(lm.require("mass", "in kg"), path + ".mass", "kg");
      link.inertia = non_negative(lm.require("inertia", "I about the centre of mass in kg m²"),
                                  path + ".inertia", "kg m²");
      read_centre_of_mass(lm, x, path, link);
      places_["links[" + std::to_string(l.links.size()) + "]"] = {path, x.key_mark};
      l.links.push_back(link);
    }
  }

  // exactly one pair: {e, f} or {s, sigma}
  void read_centre_of_mass(const MapReader& lm, const MapReader::Entry& x, const std::string& path,
                           core::planar::Link& link) {
    const CentreOfMassKeys com = centre_of_mass_keys(
        r_, lm, x, path,
        "give e [m] and f [m] (along and to the left of the line from its first node to its "
        "second), or s [m] and sigma [rad]");
    if (!com.polar()) {
      link.e = read_number(r_, *com.e, path + ".e", "m");
      link.f = read_number(r_, *com.f, path + ".f", "m");
    } else {
      const double sv = non_negative(*com.s, path + ".s", "m");
      const double sg = read_number(r_, *com.sigma, path + ".sigma", "rad");
      link.e = sv * std::cos(sg);
      link.f = sv * std::sin(sg);
    }
  }

  // point_masses: {B: 0.4, ...}
  void read_point_masses(const MapReader::Entry& e, core::planar::Linkage& l) {
    if (e.value.IsNull()) return;
    const MapReader m(r_, e.value, "linkage.point_masses", e.key_mark, "of node: mass in kg");
    for (const MapReader::Entry& x : m.entries()) {
      const std::string path = "linkage.point_masses." + x.key;
      core::planar::PointMass pm;
      pm.node = node_named(YAML::Node(x.key), x.key_mark, "linkage.point_masses", l);
      pm.mass = positive(x, path, "kg");
      places_["point_masses[" + std::to_string(l.point_masses.size()) + "]"] = {path, x.key_mark};
      l.point_masses.push_back(pm);
    }
  }

  // sliders: {piston: {node: B, guide: [[x, y], [x, y]]}, block: {node: P, guide: {link, from,
  // to}}}
  void read_sliders(const MapReader::Entry& e, core::planar::Linkage& l) {
    if (e.value.IsNull()) return;
    const MapReader m(r_, e.value, "linkage.sliders", e.key_mark, "of name: {node, guide}");
    for (const MapReader::Entry& x : m.entries()) {
      const std::string path = "linkage.sliders." + x.key;
      const MapReader sm(r_, x.value, path, x.key_mark, "(node, guide)");
      sm.check_keys({"node", "guide"});
      core::planar::Slider s;
      s.name = x.key;
      const MapReader::Entry& n = sm.require("node", "the node that slides");
      s.node = node_named(n.value, n.key_mark, path + ".node", l);
      const MapReader::Entry& g = sm.require(
          "guide",
          "a line fixed in the frame, [[x, y], [x, y]] in m, or {link, from, to} on a link");
      const std::string gp = path + ".guide";
      if (g.value.IsSequence()) {
        const YAML::Mark gm = mark_of(g.value, g.key_mark);
        if (g.value.size() != 2)
          r_.fail(gm, gp + " must be two points [[x, y], [x, y]], got " + describe(g.value));
        YAML::Mark marks[2];
        const MapReader::Entry a{"", gm, g.value[0]}, b{"", gm, g.value[1]};
        s.from = read_vec2(r_, a, gp + "[0]", "m", marks);
        s.to = read_vec2(r_, b, gp + "[1]", "m", marks);
        if (!((s.to - s.from).norm() > 0))
          r_.fail(gm, gp + ": its two points coincide (a guide of length 0)");
      } else {
        const MapReader gm(r_, g.value, gp, g.key_mark, "(link, from, to), or two points");
        gm.check_keys({"link", "from", "to"});
        const MapReader::Entry& lk = gm.require("link", "the link carrying the guide");
        s.link = link_named(lk.value, lk.key_mark, gp + ".link", l);
        const MapReader::Entry& f = gm.require("from", "a node of that link");
        const MapReader::Entry& t = gm.require("to", "another node of that link");
        s.from_node = node_named(f.value, f.key_mark, gp + ".from", l);
        s.to_node = node_named(t.value, t.key_mark, gp + ".to", l);
      }
      places_["sliders[" + std::to_string(l.sliders.size()) + "]"] = {path, x.key_mark};
      l.sliders.push_back(s);
    }
  }

  // springs: {s1: {between: [A, B], stiffness, free_length, damping}}
  void read_springs(const MapReader::Entry& e, core::planar::Linkage& l) {
    if (e.value.IsNull()) return;
    const MapReader m(r_, e.value, "linkage.springs", e.key_mark,
                      "of name: {between, stiffness, free_length, damping}");
    for (const MapReader::Entry& x : m.entries()) {
      const std::string path = "linkage.springs." + x.key;
      const MapReader sm(r_, x.value, path, x.key_mark,
                         "(between, stiffness, free_length, damping)");
      sm.check_keys({"between", "stiffness", "free_length", "damping"});
      core::planar::Spring s;
      s.name = x.key;
      const MapReader::Entry& b = sm.require("between", "its two nodes [A, B]");
      const YAML::Mark bm = mark_of(b.value, b.key_mark);
      if (!b.value.IsSequence() || b.value.size() != 2) {
        r_.fail(bm, path + ".between must be two node names [A, B], got " + describe(b.value));
      }
      s.a = node_named(b.value[0], bm, path + ".between[0]", l);
      s.b = node_named(b.value[1], bm, path + ".between[1]", l);
      if (const MapReader::Entry* k = sm.find("stiffness"))
        s.stiffness = non_negative(*k, path + ".stiffness", "N/m");
      if (const MapReader::Entry* k = sm.find("free_length"))
        s.free_length = non_negative(*k, path + ".free_length", "m");
      if (const MapReader::Entry* k = sm.find("damping"))
        s.damping = non_negative(*k, path + ".damping", "N s/m");
      places_["springs[" + std::to_string(l.springs.size()) + "]"] = {path, x.key_mark};
      l.springs.push_back(s);
    }
  }

  // balance_shafts: {S1: {link, ratio, at: [x, y], mass, eccentricity: [x, y], inertia}}
  void read_shafts(const MapReader::Entry& e, core::planar::Linkage& l) {
    if (e.value.IsNull()) return;
    const MapReader m(r_, e.value, "linkage.balance_shafts", e.key_mark,
                      "of name: {link, ratio, at, mass, eccentricity, inertia}");
    for (const MapReader::Entry& x : m.entries()) {
      const std::string path = "linkage.balance_shafts." + x.key;
      const MapReader sm(r_, x.value, path, x.key_mark,
                         "(link, ratio, at, mass, eccentricity, inertia)");
      sm.check_keys({"link", "ratio", "at", "mass", "eccentricity", "inertia"});
      core::planar::BalanceShaft b;
      b.name = x.key;
      const MapReader::Entry& k = sm.require("link", "the link it is geared to");
      b.link = link_named(k.value, k.key_mark, path + ".link", l);
      const MapReader::Entry& ratio = sm.require(
          "ratio", "its rate over the link's: -1 counter-rotates, 2 turns twice as fast");
      const double q = read_number(r_, ratio, path + ".ratio", "");
      if (q != std::round(q) || q == 0 || std::abs(q) > 1000) {
        r_.fail(mark_of(ratio.value, ratio.key_mark),
                path + ".ratio must be a whole number other than 0 (the shaft turns a whole " +
                    "number of times per turn of its link), got " + text::shortest(q));
      }
      b.ratio = static_cast<int>(q);
      YAML::Mark marks[2];
      b.at = read_vec2(r_, sm.require("at", "the shaft's position [x, y] in m"), path + ".at", "m",
                       marks);
      if (const MapReader::Entry* v = sm.find("mass"))
        b.mass = non_negative(*v, path + ".mass", "kg");
      if (const MapReader::Entry* v = sm.find("eccentricity")) {
        b.eccentricity = read_vec2(r_, *v, path + ".eccentricity", "m", marks);
      }
      if (const MapReader::Entry* v = sm.find("inertia"))
        b.inertia = non_negative(*v, path + ".inertia", "kg m²");
      places_["shafts[" + std::to_string(l.shafts.size()) + "]"] = {path, x.key_mark};
      l.shafts.push_back(b);
    }
  }

  // an effort: a number, {table: [[t, v], ...]}, or {mean, amplitude, frequency, phase}
  TimeFunction read_effort(const MapReader::Entry& x, const std::string& path, const char* unit) {
    TimeFunction f;
    if (!x.value.IsMap()) {
      f.value = read_number(r_, x, path, unit);
      return f;
    }
    const MapReader m(
        r_, x.value, path, x.key_mark,
        "a number, {table: [[t, value], ...]} or {mean, amplitude, frequency, phase}");
    if (const MapReader::Entry* t = m.find("table")) {
      m.check_keys({"table"});
      f.kind = TimeFunction::Kind::kTable;
      const YAML::Mark tm = mark_of(t->value, t->key_mark);
      if (!t->value.IsSequence() || t->value.size() == 0) {
        r_.fail(tm, path + ".table must be a list of [t, value] pairs, got " + describe(t->value));
      }
      for (std::size_t i = 0; i < t->value.size(); ++i) {
        YAML::Mark marks[2];
        const MapReader::Entry row{"", tm, t->value[i]};
        const Vec2 p = read_vec2(r_, row, path + ".table[" + std::to_string(i) + "]", unit, marks);
        if (!f.times.empty() && !(p.x() > f.times.back())) {
          r_.fail(marks[0], path + ".table: the times must increase, got " + text::shortest(p.x()) +
                                " after " + text::shortest(f.times.back()));
        }
        f.times.push_back(p.x());
        f.values.push_back(p.y());
      }
      return f;
    }
    m.check_keys({"mean", "amplitude", "frequency", "phase"});
    f.kind = TimeFunction::Kind::kHarmonic;
    if (const MapReader::Entry* v = m.find("mean"))
      f.mean = read_number(r_, *v, path + ".mean", unit);
    if (const MapReader::Entry* v = m.find("amplitude"))
      f.amplitude = read_number(r_, *v, path + ".amplitude", unit);
    if (const MapReader::Entry* v = m.find("frequency"))
      f.frequency = read_number(r_, *v, path + ".frequency", "Hz");
    if (const MapReader::Entry* v = m.find("phase"))
      f.phase = read_number(r_, *v, path + ".phase", "rad");
    return f;
  }

  // inputs: {crank: {link: crank, torque: 0}, stroke: {slider: piston, force: 0}}
  void read_inputs(const MapReader::Entry& e, core::planar::Linkage& l) {
    const MapReader m(r_, e.value, "linkage.inputs", e.key_mark,
                      "of name: {link} (its angle) or {slider} (its position)");
    for (const MapReader::Entry& x : m.entries()) {
      const std::string path = "linkage.inputs." + x.key;
      const MapReader im(r_, x.value, path, x.key_mark, "(link and torque, or slider and force)");
      Input in;
      in.name = x.key;
      if (const MapReader::Entry* lk = im.find("link")) {
        im.check_keys({"link", "torque"}, " in " + path + " (an angle input)");
        in.kind = Input::Kind::kAngle;
        in.link = link_named(lk->value, lk->key_mark, path + ".link", l);
        if (const MapReader::Entry* t = im.find("torque"))
          in.effort = read_effort(*t, path + ".torque", "N m");
      } else if (const MapReader::Entry* sl = im.find("slider")) {
        im.check_keys({"slider", "force"}, " in " + path + " (a slide input)");
        in.kind = Input::Kind::kSlide;
        in.slider = slider_named(sl->value, sl->key_mark, path + ".slider", l);
        if (const MapReader::Entry* f = im.find("force"))
          in.effort = read_effort(*f, path + ".force", "N");
      } else {
        r_.fail(x.key_mark, path +
                                " needs link (the link's angle is the input) or slider (its "
                                "position along the guide is)");
      }
      places_["inputs[" + std::to_string(l.inputs.size()) + "]"] = {path, x.key_mark};
      l.inputs.push_back(in);
    }
  }

  int slider_named(const YAML::Node& v, const YAML::Mark& fallback, const std::string& path,
                   const core::planar::Linkage& l) {
    for (std::size_t i = 0; i < l.sliders.size(); ++i) {
      if (v.IsScalar() && l.sliders[i].name == v.Scalar()) return static_cast<int>(i);
    }
    std::vector<std::string> names;
    for (const core::planar::Slider& s : l.sliders) names.push_back(s.name);
    r_.fail(mark_of(v, fallback), path + ": unknown slider " + describe(v) +
                                      (names.empty() ? "; the linkage has no sliders"
                                                     : "; the sliders are " + join(names)));
  }

  // loads: {gravity, links: {<link>: {force, moment}}, nodes: {<node>: {force}}}
  void read_loads(const MapReader::Entry& e, core::planar::Linkage& l) {
    if (e.value.IsNull()) return;
    const MapReader m(r_, e.value, "loads", e.key_mark, "(gravity, links, nodes)");
    m.check_keys({"gravity", "links", "nodes"});
    if (const MapReader::Entry* g = m.find("gravity")) {
      YAML::Mark marks[2];
      l.loads.gravity = read_vec2(r_, *g, "loads.gravity", "m/s²", marks);
    }
    if (const MapReader::Entry* x = m.find("links"); x && !x->value.IsNull()) {
      const MapReader lm(r_, x->value, "loads.links", x->key_mark, "of link: {force, moment}");
      for (const MapReader::Entry& y : lm.entries()) {
        const std::string path = "loads.links." + y.key;
        core::planar::LinkLoad ld;
        ld.link = link_named(YAML::Node(y.key), y.key_mark, "loads.links", l);
        const MapReader fm(r_, y.value, path, y.key_mark, "(force, moment)");
        fm.check_keys({"force", "moment"});
        YAML::Mark marks[2];
        if (const MapReader::Entry* f = fm.find("force"))
          ld.force = read_vec2(r_, *f, path + ".force", "N", marks);
        if (const MapReader::Entry* mo = fm.find("moment"))
          ld.moment = read_number(r_, *mo, path + ".moment", "N m");
        l.loads.link_loads.push_back(ld);
      }
    }
    if (const MapReader::Entry* x = m.find("nodes"); x && !x->value.IsNull()) {
      const MapReader nm(r_, x->value, "loads.nodes", x->key_mark, "of node: {force}");
      for (const MapReader::Entry& y : nm.entries()) {
        const std::string path = "loads.nodes." + y.key;
        core::planar::NodeForce nf;
        nf.node = node_named(YAML::Node(y.key), y.key_mark, "loads.nodes", l);
        if (l.nodes[static_cast<std::size_t>(nf.node)].ground) {
          r_.fail(y.key_mark, path + ": node " + y.key +
                                  " is fixed to the frame; a force there acts on the frame, not on "
                                  "the mechanism");
        }
        const MapReader fm(r_, y.value, path, y.key_mark, "(force)");
        fm.check_keys({"force"});
        YAML::Mark marks[2];
        nf.force = read_vec2(r_, fm.require("force", "[Fx, Fy] in N"), path + ".force", "N", marks);
        l.loads.node_forces.push_back(nf);
      }
    }
  }

  // make_linkage(), the mobility and the drawn closure, each complaint at its item's place
  core::planar::Linkage checked(const core::planar::Linkage& l, const MapReader::Entry& inputs) {
    try {
      const core::planar::Linkage checked = core::planar::make_linkage(l);
      const core::planar::Model model(checked);
      const int m = core::planar::mobility(model);
      if (m != static_cast<int>(checked.inputs.size())) {
        r_.fail(
            inputs.key_mark,
            "linkage.inputs: the linkage has " + std::to_string(m) + " degree" +
                (m == 1 ? "" : "s") + " of freedom and " + std::to_string(checked.inputs.size()) +
                " input" + (checked.inputs.size() == 1 ? "" : "s") +
                "; give one input (a link's angle or a slider's position) per degree of freedom");
      }
      if (auto ok = core::planar::check_drawn(model); !ok) {
        r_.fail(linkage_mark_, "linkage: " + ok.error().detail);
      }
      return checked;
    } catch (const StudyError&) {
      throw;  // already placed
    } catch (const InputError& err) {
      if (const auto& f = err.field()) {
        const auto it = places_.find(f->field + "[" + std::to_string(f->index) + "]");
        if (it != places_.end()) r_.fail(it->second.mark, f->joined(it->second.path));
      }
      r_.fail(linkage_mark_, "linkage: " + std::string(err.what()));
    }
  }

  // ---- the scene

  // a list with one value per input (a plain number for a single input)
  // one value per input, each in its input's unit (an angle's or a slide's, or their rates')
  std::vector<double> read_values(const MapReader::Entry& x, const std::string& path,
                                  std::size_t n, const core::planar::Linkage& l, bool rate) {
    auto unit = [&](std::size_t i) -> std::string {
      const bool angle =
          i >= l.inputs.size() || l.inputs[i].kind == core::planar::Input::Kind::kAngle;
      return angle ? (rate ? "rad/s" : "rad") : (rate ? "m/s" : "m");
    };
    if (x.value.IsScalar() && n == 1) return {read_number(r_, x, path, unit(0))};
    const YAML::Mark m = mark_of(x.value, x.key_mark);
    if (!x.value.IsSequence() || x.value.size() != n) {
      r_.fail(m, path + " must be a list of " + std::to_string(n) + " number" +
                     (n == 1 ? "" : "s") +
                     " (one per input, in the order of linkage.inputs), got " + describe(x.value));
    }
    std::vector<double> v;
    for (std::size_t i = 0; i < n; ++i) {
      v.push_back(read_number(r_, x.value[i], m, path + "[" + std::to_string(i) + "]", unit(i)));
    }
    return v;
  }

  // the linkage assembles at the scene's start (empty: as drawn)
  void check_start(const MapReader::Entry& e, const core::planar::Model& model,
                   const std::vector<double>& start) {
    core::planar::Workspace ws(model);
    const auto ok = core::planar::assemble(
        model, ws, start.empty() ? core::planar::drawn_inputs(model) : start);
    if (!ok) r_.fail(e.key_mark, "scene: " + ok.error().detail + " (the start of the scene)");
  }

  // a driven scene over whole revolutions, or over its duration: refused at scene.type when the
  // linkage cannot be assembled somewhere in the first revolution (or the duration), as the
  // four-bar's crank that cannot turn fully is (the run would stop at the first limit position).
  // The motion is stepped as the run steps it (at its samples, at most 3600), positions and
  // dynamics; a singular position on an assembly that goes on (a dead centre) stops the run
  // there instead, with the samples before.
  void check_turns(const MapReader::Entry& e, const MapReader::Entry& type,
                   const core::planar::Model& model, const core::planar::DrivenScene& d) {
    core::planar::DrivenScene one = d;
    one.revolutions = 1;  // (a scene by duration: its whole duration)
    one.samples = std::min(d.samples, kTurnCheckSamples);
    core::planar::Trajectory run;
    try {
      run = core::planar::simulate_driven(model, one);
    } catch (const InputError& err) {
      r_.fail(e.key_mark, "scene: " + std::string(err.what()));
    }
    if (run.status != core::SimulationStatus::kAssemblyFailed) return;
    r_.fail(mark_of(type.value, type.key_mark),
            std::string(d.duration > 0 ? "scene.type: driven moves the inputs at their speeds "
                                         "for the whole duration, but "
                                       : "scene.type: driven turns the inputs through whole "
                                         "revolutions, but ") +
                run.message +
                ", so the run would stop there; simulate it with type: free, which passes the "
                "limit positions where the linkage does, " +
                (d.duration > 0 ? "shorten the duration, " : "") + "or change the link lengths");
  }
  static constexpr int kTurnCheckSamples = 3600;

  struct Place {
    std::string path;
    YAML::Mark mark;
  };

  const Reporter& r_;
  YAML::Mark linkage_mark_;
  std::map<std::string, Place> places_;  // "links[2]" -> linkage.links.coupler and its key

 public:
  std::vector<CounterweightPart> parts_;  // linkage.counterweights, in file order
  std::optional<LinkageParts> parts;      // set by read() when there are any
};

PlanarSection::PlanarSection(const Reporter& r) : impl_(std::make_unique<Impl>(r)) {}
PlanarSection::~PlanarSection() = default;

core::planar::Linkage PlanarSection::read(const MapReader::Entry& linkage,
                                          const MapReader::Entry* loads) {
  return impl_->read(linkage, loads);
}

std::optional<LinkageParts> PlanarSection::parts() const { return impl_->parts; }

Scene PlanarSection::read_scene(const MapReader::Entry& scene,
                                const core::planar::Linkage& linkage) {
  return impl_->read_scene(scene, linkage);
}

}  // namespace bd::studies::detail
