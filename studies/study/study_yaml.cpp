#include "studies/study/study_yaml.hpp"

#include <cstdio>
#include <sstream>
#include <variant>

#include "core/number_text.hpp"

namespace bd::studies {

namespace {

std::string vec(const Vec2& v) {
  return "[" + text::exact(v.x()) + ", " + text::exact(v.y()) + "]";
}

// the paper's polar form s, sigma (what people read and what the issue asks for); reading it
// back reproduces e, f to within a few ulps (s e^{i sigma} rounds), which the comment records
std::string link_line(const char* name, const core::Link& l) {
  return std::string("  ") + name + ": {length: " + text::exact(l.length) +
         ", mass: " + text::exact(l.mass) + ", s: " + text::exact(l.s()) +
         ", sigma: " + text::exact(l.sigma()) + ", inertia: " + text::exact(l.inertia) + "}\n" +
         "    # e = " + text::exact(l.e) + " m, f = " + text::exact(l.f) + " m\n";
}

std::string load_line(const char* name, const core::LinkLoad& l) {
  return std::string("  ") + name + ": {force: " + vec(l.force) +
         ", moment: " + text::exact(l.moment) + "}\n";
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

  // linkage: links in the paper's polar form (see link_line)
  const core::FourBar& m = study.fourbar();
  y += "linkage:\n";
  y += "  type: fourbar\n";
  y += "  frame: " + text::exact(m.frame_length) + "\n";
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
      y += std::string("    ") + disc_names[i] + ": {inertia: " + text::exact(discs[i]->inertia) +
           ", at: " + vec(discs[i]->at) + "}\n";
    }
  }

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
    y += "  theta1: " + text::exact(free->theta1) + "\n";
    y += "  omega1: " + text::exact(free->omega1) + "\n";
    y += "  duration: " + text::exact(free->duration) + "\n";
    y += "  samples: " + std::to_string(free->samples) + "\n";
  } else {
    const auto& driven = std::get<core::DrivenScene>(study.scene);
    y += "  type: driven\n";
    y += "  theta1: " + text::exact(driven.theta1) + "\n";
    y += "  omega1: " + text::exact(driven.omega1) + "\n";
    y += "  revolutions: " + std::to_string(driven.revolutions) + "\n";
    y += "  samples: " + std::to_string(driven.samples) + "\n";
  }
  y += "\nmethod: " + study.method_name() + "\n";
  y += "tolerance: " + text::exact(study.tolerance) + "\n";
  return y;
}

}  // namespace bd::studies
