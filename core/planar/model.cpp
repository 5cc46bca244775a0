#include "core/planar/model.hpp"

#include <algorithm>
#include <cmath>
#include <set>

#include "core/input_error.hpp"
#include "core/number_text.hpp"

namespace bd::core::planar {

namespace {

[[noreturn]] void fail(const char* list, std::size_t index, const std::string& message) {
  throw InputError(FieldError{list, static_cast<int>(index), message});
}

bool finite(const Vec2& v) { return std::isfinite(v.x()) && std::isfinite(v.y()); }

void check_name(const char* list, std::size_t index, const std::string& name,
                std::set<std::string>& seen) {
  if (name.empty()) fail(list, index, ": a name is needed");
  if (!seen.insert(name).second) fail(list, index, ": the name '" + name + "' is used twice");
}

void check_node(const Linkage& l, const char* list, std::size_t index, const char* what, int node) {
  if (node < 0 || node >= static_cast<int>(l.nodes.size())) {
    fail(list, index,
         std::string(": ") + what + " is not a node (index " + std::to_string(node) + ")");
  }
}

void check_value(const char* list, std::size_t index, const char* key, double v, bool ok,
                 const char* expected, const char* unit) {
  if (!ok || !std::isfinite(v)) {
    fail(list, index,
         std::string(".") + key + " must be " + expected + (unit[0] ? " " : "") + unit + ", got " +
             text::shortest(v));
  }
}

void check_links(const Linkage& l) {
  std::set<std::string> names;
  for (std::size_t k = 0; k < l.links.size(); ++k) {
    const Link& link = l.links[k];
    check_name("links", k, link.name, names);
    if (link.nodes.size() < 2) {
      fail("links", k, " must join at least 2 nodes, got " + std::to_string(link.nodes.size()));
    }
    std::set<int> seen;
    for (int n : link.nodes) {
      check_node(l, "links", k, "a node of the link", n);
      if (!seen.insert(n).second) {
        fail("links", k, " names node " + l.nodes[static_cast<std::size_t>(n)].name + " twice");
      }
    }
    const Vec2 d = l.nodes[static_cast<std::size_t>(link.nodes[1])].position -
                   l.nodes[static_cast<std::size_t>(link.nodes[0])].position;
    if (!(d.norm() > 0)) {
      fail("links", k,
           ": its first two nodes " + l.nodes[static_cast<std::size_t>(link.nodes[0])].name +
               " and " + l.nodes[static_cast<std::size_t>(link.nodes[1])].name +
               " coincide; they set the link's length and direction");
    }
    check_value("links", k, "mass", link.mass, link.mass >= 0, ">= 0", "kg");
    check_value("links", k, "e", link.e, true, "finite", "m");
    check_value("links", k, "f", link.f, true, "finite", "m");
    check_value("links", k, "inertia", link.inertia, link.inertia >= 0, ">= 0", "kg m²");
  }
}

void check_sliders(const Linkage& l) {
  std::set<std::string> names;
  for (std::size_t k = 0; k < l.sliders.size(); ++k) {
    const Slider& s = l.sliders[k];
    check_name("sliders", k, s.name, names);
    check_node(l, "sliders", k, "the sliding node", s.node);
    if (l.nodes[static_cast<std::size_t>(s.node)].ground) {
      fail("sliders", k,
           ": its node " + l.nodes[static_cast<std::size_t>(s.node)].name +
               " is fixed to the frame and cannot slide");
    }
    if (s.link < 0) {
      if (!finite(s.from) || !finite(s.to) || !((s.to - s.from).norm() > 0)) {
        fail("sliders", k, ": the guide needs two distinct finite points");
      }
      continue;
    }
    if (s.link >= static_cast<int>(l.links.size())) fail("sliders", k, ": not a link");
    const auto& nodes = l.links[static_cast<std::size_t>(s.link)].nodes;
    for (int n : {s.from_node, s.to_node}) {
      check_node(l, "sliders", k, "a guide node", n);
      if (std::find(nodes.begin(), nodes.end(), n) == nodes.end()) {
        fail("sliders", k,
             ": the guide's node " + l.nodes[static_cast<std::size_t>(n)].name +
                 " is not on link " + l.links[static_cast<std::size_t>(s.link)].name);
      }
    }
    if (s.from_node == s.to_node || !((l.nodes[static_cast<std::size_t>(s.to_node)].position -
                                       l.nodes[static_cast<std::size_t>(s.from_node)].position)
                                          .norm() > 0)) {
      fail("sliders", k, ": the guide's two nodes coincide (a guide of length 0)");
    }
    if (std::find(nodes.begin(), nodes.end(), s.node) != nodes.end()) {
      fail("sliders", k, ": the sliding node is on the guide's own link");
    }
  }
}

void check_inputs(const Linkage& l) {
  std::set<std::string> names;
  for (std::size_t k = 0; k < l.inputs.size(); ++k) {
    const Input& in = l.inputs[k];
    check_name("inputs", k, in.name, names);
    if (in.kind == Input::Kind::kAngle) {
      if (in.link < 0 || in.link >= static_cast<int>(l.links.size()))
        fail("inputs", k, ": not a link");
      const Link& link = l.links[static_cast<std::size_t>(in.link)];
      const bool grounded = std::any_of(link.nodes.begin(), link.nodes.end(), [&](int n) {
        return l.nodes[static_cast<std::size_t>(n)].ground;
      });
      if (!grounded) {
        fail("inputs", k,
             ": link " + link.name +
                 " has no ground node to turn about (a drive acts between the frame "
                 "and a link pivoted on it)");
      }
    } else if (in.slider < 0 || in.slider >= static_cast<int>(l.sliders.size())) {
      fail("inputs", k, ": not a slider");
    }
    const TimeFunction& f = in.effort;
    if (f.kind == TimeFunction::Kind::kTable) {
      if (f.times.size() != f.values.size() || f.times.empty()) {
        fail("inputs", k, ".effort: a table needs as many values as times, at least one");
      }
      for (std::size_t i = 1; i < f.times.size(); ++i) {
        if (!(f.times[i] > f.times[i - 1])) fail("inputs", k, ".effort: times must increase");
      }
    }
  }
}

void check_others(const Linkage& l) {
  for (std::size_t k = 0; k < l.point_masses.size(); ++k) {
    const PointMass& pm = l.point_masses[k];
    check_node(l, "point_masses", k, "its node", pm.node);
    if (l.nodes[static_cast<std::size_t>(pm.node)].ground) {
      fail("point_masses", k,
           ": node " + l.nodes[static_cast<std::size_t>(pm.node)].name +
               " is fixed to the frame; a mass there never moves");
    }
    check_value("point_masses", k, "mass", pm.mass, pm.mass > 0, "> 0", "kg");
  }
  std::set<std::string> names;
  for (std::size_t k = 0; k < l.springs.size(); ++k) {
    const Spring& s = l.springs[k];
    check_name("springs", k, s.name, names);
    check_node(l, "springs", k, "an end", s.a);
    check_node(l, "springs", k, "an end", s.b);
    if (s.a == s.b) fail("springs", k, ": both ends are the same node");
    if (l.nodes[static_cast<std::size_t>(s.a)].ground &&
        l.nodes[static_cast<std::size_t>(s.b)].ground) {
      fail("springs", k, ": both ends are fixed to the frame");
    }
    check_value("springs", k, "stiffness", s.stiffness, s.stiffness >= 0, ">= 0", "N/m");
    check_value("springs", k, "free_length", s.free_length, s.free_length >= 0, ">= 0", "m");
    check_value("springs", k, "damping", s.damping, s.damping >= 0, ">= 0", "N s/m");
  }
  if (!finite(l.loads.gravity)) throw InputError(FieldError{"loads.gravity", -1, "must be finite"});
  for (std::size_t k = 0; k < l.loads.node_forces.size(); ++k) {
    const NodeForce& f = l.loads.node_forces[k];
    check_node(l, "loads.node_forces", k, "its node", f.node);
    if (l.nodes[static_cast<std::size_t>(f.node)].ground) {
      fail("loads.node_forces", k,
           ": node " + l.nodes[static_cast<std::size_t>(f.node)].name +
               " is fixed to the frame; a force there acts on the frame");
    }
    if (!finite(f.force)) fail("loads.node_forces", k, ".force must be finite");
  }
  for (std::size_t k = 0; k < l.loads.link_loads.size(); ++k) {
    const LinkLoad& ld = l.loads.link_loads[k];
    if (ld.link < 0 || ld.link >= static_cast<int>(l.links.size()))
      fail("loads.link_loads", k, ": not a link");
    if (!finite(ld.force) || !std::isfinite(ld.moment)) {
      fail("loads.link_loads", k, ": force and moment must be finite");
    }
  }
}

void check_shafts(const Linkage& l) {
  std::set<std::string> names;
  for (const Node& n : l.nodes) names.insert(n.name);
  for (const Slider& s : l.sliders) names.insert(s.name);
  for (std::size_t k = 0; k < l.shafts.size(); ++k) {
    const BalanceShaft& b = l.shafts[k];
    if (b.name.empty()) fail("shafts", k, ": a name is needed");
    if (!names.insert(b.name).second) {
      fail("shafts", k,
           ": the name '" + b.name +
               "' is a node's, a slider's or another shaft's (its reaction is R" + b.name + ")");
    }
    if (b.link < 0 || b.link >= static_cast<int>(l.links.size())) fail("shafts", k, ": not a link");
    if (pivot_of(l, b.link) < 0) {
      fail("shafts", k,
           ": link " + l.links[static_cast<std::size_t>(b.link)].name +
               " does not turn about one ground node; a balance shaft is geared to a link "
               "pivoted on the frame");
    }
    if (b.ratio == 0) fail("shafts", k, ".ratio must be a non-zero integer, got 0");
    if (!finite(b.at)) fail("shafts", k, ".at must be finite");
    if (!finite(b.eccentricity)) fail("shafts", k, ".eccentricity must be finite");
    check_value("shafts", k, "mass", b.mass, b.mass >= 0, ">= 0", "kg");
    check_value("shafts", k, "inertia", b.inertia, b.inertia >= 0, ">= 0", "kg m²");
  }
}

}  // namespace

double TimeFunction::operator()(double t) const {
  switch (kind) {
    case Kind::kConstant:
      return value;
    case Kind::kHarmonic:
      return mean + amplitude * std::sin(2 * 3.14159265358979323846 * frequency * t + phase);
    case Kind::kTable: {
      if (t <= times.front()) return values.front();
      if (t >= times.back()) return values.back();
      const auto it = std::upper_bound(times.begin(), times.end(), t);
      const std::size_t i = static_cast<std::size_t>(it - times.begin());
      const double w = (t - times[i - 1]) / (times[i] - times[i - 1]);
      return values[i - 1] + w * (values[i] - values[i - 1]);
    }
  }
  return 0.0;
}

Linkage make_linkage(const Linkage& candidate) {
  const Linkage& l = candidate;
  std::set<std::string> names;
  for (std::size_t i = 0; i < l.nodes.size(); ++i) {
    check_name("nodes", i, l.nodes[i].name, names);
    if (!finite(l.nodes[i].position)) fail("nodes", i, " must be at a finite position");
  }
  if (l.links.empty())
    throw InputError(FieldError{"links", -1, ": a linkage needs at least one link"});
  check_links(l);
  check_sliders(l);
  check_inputs(l);
  check_others(l);
  check_shafts(l);
  return candidate;
}

int node_index(const Linkage& l, const std::string& name) {
  for (std::size_t i = 0; i < l.nodes.size(); ++i) {
    if (l.nodes[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

int link_index(const Linkage& l, const std::string& name) {
  for (std::size_t i = 0; i < l.links.size(); ++i) {
    if (l.links[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

double element_length(const Linkage& l, int k) {
  const Link& link = l.links[static_cast<std::size_t>(k)];
  return (l.nodes[static_cast<std::size_t>(link.nodes[1])].position -
          l.nodes[static_cast<std::size_t>(link.nodes[0])].position)
      .norm();
}

Vec2 shaft_centre(const BalanceShaft& b, double link_turn) {
  const double turned = b.ratio * link_turn, c = std::cos(turned), s = std::sin(turned);
  return {c * b.eccentricity.x() - s * b.eccentricity.y(),
          s * b.eccentricity.x() + c * b.eccentricity.y()};
}

int pivot_of(const Linkage& l, int link) {
  int pivot = -1;
  for (int n : l.links[static_cast<std::size_t>(link)].nodes) {
    if (!l.nodes[static_cast<std::size_t>(n)].ground) continue;
    if (pivot >= 0) return -1;
    pivot = n;
  }
  return pivot;
}

double total_mass(const Linkage& l) {
  double m = 0;
  for (const Link& link : l.links) m += link.mass;
  for (const PointMass& pm : l.point_masses) m += pm.mass;
  for (const BalanceShaft& b : l.shafts) m += b.mass;
  return m;
}

int mass_parameter_count(const Linkage& l) {
  return 4 * static_cast<int>(l.links.size()) + static_cast<int>(l.point_masses.size());
}

std::vector<double> mass_parameters(const Linkage& l) {
  std::vector<double> pi;
  pi.reserve(static_cast<std::size_t>(mass_parameter_count(l)));
  for (const Link& link : l.links) {
    pi.insert(pi.end(), {link.mass, link.mass * link.e, link.mass * link.f,
                         link.inertia + link.mass * (link.e * link.e + link.f * link.f)});
  }
  for (const PointMass& pm : l.point_masses) pi.push_back(pm.mass);
  return pi;
}

void set_mass_parameters(Linkage& l, const double* pi) {
  for (Link& link : l.links) {
    link.mass = pi[0];
    link.e = link.mass != 0 ? pi[1] / link.mass : 0.0;
    link.f = link.mass != 0 ? pi[2] / link.mass : 0.0;
    link.inertia = pi[3] - link.mass * (link.e * link.e + link.f * link.f);
    pi += 4;
  }
  for (PointMass& pm : l.point_masses) pm.mass = *pi++;
}

Linkage with_mass_parameters(const Linkage& l, const double* pi) {
  Linkage out = l;
  set_mass_parameters(out, pi);
  return out;
}

}  // namespace bd::core::planar
