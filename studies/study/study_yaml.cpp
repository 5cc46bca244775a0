#include "studies/study/study_yaml.hpp"

#include <cstdio>
#include <sstream>
#include <variant>

#include "core/number_text.hpp"

namespace bd::studies {

namespace {

// a number as the study file has it: shortest exact, a negative zero (a mirrored 0) as 0
std::string num(double v) { return text::shortest(v == 0 ? 0.0 : v); }

std::string vec(const Vec2& v) { return "[" + num(v.x()) + ", " + num(v.y()) + "]"; }

// e, f exactly (they read back bit for bit); the paper's polar form s, sigma as a comment for a
// person (12 digits: sigma = 0.4, not the 0.4000000000000001 its atan2 gives)
std::string link_line(const char* name, const core::Link& l) {
  return std::string("  ") + name + ": {length: " + num(l.length) + ", mass: " + num(l.mass) +
         ", e: " + num(l.e) + ", f: " + num(l.f) + ", inertia: " + num(l.inertia) + "}\n" +
         "    # s = " + text::digits(l.s(), 12) + " m, sigma = " + text::digits(l.sigma(), 12) +
         " rad\n";
}

// linkage.counterweights: each part's mass, centre in link axes from its pivot, own inertia
std::string counterweights_yaml(const std::vector<CounterweightPart>& parts,
                                const core::planar::Linkage* l) {
  if (parts.empty()) return "";
  std::string y =
      "  counterweights:  # parts of their links: merged into them (parallel axes) on reading\n";
  for (const CounterweightPart& p : parts) {
    const balance::Counterweight& c = p.counterweight;
    const std::string from =
        l ? "from: " + l->nodes[static_cast<std::size_t>(p.pivot)].name + ", " : std::string();
    const std::string name =
        l ? l->links[static_cast<std::size_t>(p.link)].name : std::string(p.link == 1 ? "crank" : "rocker");
    y += "    " + name + ": {" + from + "mass: " + num(c.mass) + ", at: " + vec(c.position) +
         ", inertia: " + num(c.inertia) + "}\n";
  }
  return y;
}

std::string load_line(const char* name, const core::LinkLoad& l) {
  return std::string("  ") + name + ": {force: " + vec(l.force) + ", moment: " + num(l.moment) +
         "}\n";
}

std::string list(const std::vector<double>& v) {
  std::string s = "[";
  for (std::size_t k = 0; k < v.size(); ++k) s += (k ? ", " : "") + num(v[k]);
  return s + "]";
}

std::string effort(const core::planar::TimeFunction& f) {
  using K = core::planar::TimeFunction::Kind;
  if (f.kind == K::kConstant) return num(f.value);
  if (f.kind == K::kHarmonic) {
    return "{mean: " + num(f.mean) + ", amplitude: " + num(f.amplitude) +
           ", frequency: " + num(f.frequency) + ", phase: " + num(f.phase) + "}";
  }
  std::string s = "{table: [";
  for (std::size_t k = 0; k < f.times.size(); ++k) {
    s += (k ? ", [" : "[") + num(f.times[k]) + ", " + num(f.values[k]) + "]";
  }
  return s + "]}";
}

// a planar linkage's linkage and loads sections (names are plain: letters, digits, '_', '-')
std::string planar_linkage_yaml(const core::planar::Linkage& l,
                                const std::vector<CounterweightPart>& parts) {
  auto node = [&](int i) { return l.nodes[static_cast<std::size_t>(i)].name; };
  std::string y = "linkage:\n  type: planar\n  nodes:\n";
  for (const core::planar::Node& n : l.nodes) {
    y += "    " + n.name + ": {at: " + vec(n.position) + (n.ground ? ", ground: true" : "") + "}\n";
  }
  y += "  links:\n";
  for (const core::planar::Link& k : l.links) {
    std::string nodes;
    for (int i : k.nodes) nodes += (nodes.empty() ? "" : ", ") + node(i);
    y += "    " + k.name + ": {nodes: [" + nodes + "], mass: " + num(k.mass) + ", e: " + num(k.e) +
         ", f: " + num(k.f) + ", inertia: " + num(k.inertia) + "}\n";
  }
  if (!l.point_masses.empty()) {
    y += "  point_masses:\n";
    for (const core::planar::PointMass& p : l.point_masses) {
      y += "    " + node(p.node) + ": " + num(p.mass) + "\n";
    }
  }
  if (!l.sliders.empty()) {
    y += "  sliders:\n";
    for (const core::planar::Slider& sl : l.sliders) {
      const std::string guide =
          sl.link < 0 ? "[" + vec(sl.from) + ", " + vec(sl.to) + "]"
                      : "{link: " + l.links[static_cast<std::size_t>(sl.link)].name +
                            ", from: " + node(sl.from_node) + ", to: " + node(sl.to_node) + "}";
      y += "    " + sl.name + ": {node: " + node(sl.node) + ", guide: " + guide + "}\n";
    }
  }
  if (!l.springs.empty()) {
    y += "  springs:\n";
    for (const core::planar::Spring& sp : l.springs) {
      y += "    " + sp.name + ": {between: [" + node(sp.a) + ", " + node(sp.b) +
           "], stiffness: " + num(sp.stiffness) + ", free_length: " + num(sp.free_length) +
           ", damping: " + num(sp.damping) + "}\n";
    }
  }
  if (!l.shafts.empty()) {
    y += "  balance_shafts:\n";
    for (const core::planar::BalanceShaft& b : l.shafts) {
      y += "    " + b.name + ": {link: " + l.links[static_cast<std::size_t>(b.link)].name +
           ", ratio: " + std::to_string(b.ratio) + ", at: " + vec(b.at) + ", mass: " + num(b.mass) +
           ", eccentricity: " + vec(b.eccentricity) + ", inertia: " + num(b.inertia) + "}\n";
    }
  }
  y += counterweights_yaml(parts, &l);
  y += "  inputs:\n";
  for (const core::planar::Input& in : l.inputs) {
    if (in.kind == core::planar::Input::Kind::kAngle) {
      y += "    " + in.name + ": {link: " + l.links[static_cast<std::size_t>(in.link)].name +
           ", torque: " + effort(in.effort) + "}\n";
    } else {
      y += "    " + in.name + ": {slider: " + l.sliders[static_cast<std::size_t>(in.slider)].name +
           ", force: " + effort(in.effort) + "}\n";
    }
  }
  y += "\nloads:\n  gravity: " + vec(l.loads.gravity) + "\n";
  if (!l.loads.link_loads.empty()) {
    y += "  links:\n";
    for (const core::planar::LinkLoad& ld : l.loads.link_loads) {
      y += "    " + l.links[static_cast<std::size_t>(ld.link)].name + ": {force: " + vec(ld.force) +
           ", moment: " + num(ld.moment) + "}\n";
    }
  }
  if (!l.loads.node_forces.empty()) {
    y += "  nodes:\n";
    for (const core::planar::NodeForce& nf : l.loads.node_forces) {
      y += "    " + node(nf.node) + ": {force: " + vec(nf.force) + "}\n";
    }
  }
  return y;
}

std::string planar_scene_yaml(const Scene& scene) {
  std::string y = "\nscene:\n";
  if (const auto* f = std::get_if<core::planar::FreeScene>(&scene)) {
    y += "  type: free\n";
    if (!f->start.empty()) y += "  start: " + list(f->start) + "\n";
    if (!f->rates.empty()) y += "  rates: " + list(f->rates) + "\n";
    y += "  duration: " + num(f->duration) + "\n";
    return y + "  samples: " + std::to_string(f->samples) + "\n";
  }
  const auto& d = std::get<core::planar::DrivenScene>(scene);
  y += "  type: driven\n";
  if (!d.start.empty()) y += "  start: " + list(d.start) + "\n";
  y += "  speeds: " + list(d.speeds) + "\n";
  if (d.duration > 0) {
    y += "  duration: " + num(d.duration) + "\n";
  } else {
    y += "  revolutions: " + std::to_string(d.revolutions) + "\n";
  }
  return y + "  samples: " + std::to_string(d.samples) + "\n";
}

}  // namespace

std::string study_yaml(const Study& study, const std::string& header) {
  std::string y;
  // header comment, one `# ` line per line
  if (!header.empty()) {
    std::istringstream in(header);
    for (std::string line; std::getline(in, line);) y += line.empty() ? "#\n" : "# " + line + "\n";
    y += "\n";
  }
  y += "name: \"" + study.name + "\"\n\n";  // letters, digits, '.', '_', '-': no escapes needed
  // the links without their counterweight parts, and the parts, when the study has any
  const Linkage& linkage = study.parts ? study.parts->bare : study.linkage;
  const std::vector<CounterweightPart> no_parts;
  const std::vector<CounterweightPart>& parts = study.parts ? study.parts->counterweights : no_parts;
  if (!study.is_fourbar()) {
    y += planar_linkage_yaml(std::get<core::planar::Linkage>(linkage), parts) +
         planar_scene_yaml(study.scene);
    y += "\nmethod: " + study.method_name() + "\n";
    return y + "tolerance: " + num(study.tolerance) + "\n";
  }

  // linkage: links with e, f (see link_line)
  const core::FourBar& m = std::get<core::FourBar>(linkage);
  y += "linkage:\n";
  y += "  type: fourbar\n";
  y += "  frame: " + num(m.frame_length) + "\n";
  y += std::string("  branch: ") + (m.branch == core::Branch::kPlus ? "1" : "-1") + "\n";
  y += link_line("crank", m.crank);
  y += link_line("coupler", m.coupler);
  y += link_line("rocker", m.rocker);
  const core::CounterRotation* discs[] = {&m.counter_rotations.crank, &m.counter_rotations.rocker};
  const char* disc_names[] = {"crank", "rocker"};
  if (core::has_counter_rotations(m)) {
    y += "  counter_rotations:\n";
    for (int i = 0; i < 2; ++i) {
      if (discs[i]->inertia <= 0) continue;
      y += std::string("    ") + disc_names[i] + ": {inertia: " + num(discs[i]->inertia) +
           ", at: " + vec(discs[i]->at) + "}\n";
    }
  }
  y += counterweights_yaml(parts, nullptr);

  // loads: every value, zero or not
  y += "\nloads:\n";
  y += "  gravity: " + vec(m.loads.gravity) + "\n";
  y += load_line("crank", m.loads.crank);
  y += load_line("coupler", m.loads.coupler);
  y += load_line("rocker", m.loads.rocker);

  // scene with every key, defaults written out
  y += "\nscene:\n";
  if (const auto* free = std::get_if<core::FreeScene>(&study.scene)) {
    y += "  type: free\n";
    y += "  theta1: " + num(free->theta1) + "\n";
    y += "  omega1: " + num(free->omega1) + "\n";
    y += "  duration: " + num(free->duration) + "\n";
    y += "  samples: " + std::to_string(free->samples) + "\n";
  } else {
    const auto& driven = std::get<core::DrivenScene>(study.scene);
    y += "  type: driven\n";
    y += "  theta1: " + num(driven.theta1) + "\n";
    y += "  omega1: " + num(driven.omega1) + "\n";
    y += "  revolutions: " + std::to_string(driven.revolutions) + "\n";
    y += "  samples: " + std::to_string(driven.samples) + "\n";
  }
  y += "\nmethod: " + study.method_name() + "\n";
  y += "tolerance: " + num(study.tolerance) + "\n";
  return y;
}

}  // namespace bd::studies
