#include "core/planar/metrics.hpp"

#include <algorithm>
#include <cmath>

namespace bd::core::planar {

std::vector<ColumnMetric> metric_table(const Model& model) {
  const Linkage& l = model.linkage();
  std::vector<ColumnMetric> t;
  auto both = [&](const std::string& symbol, const char* unit, const std::string& what,
                  std::vector<std::string> columns) {
    t.push_back({symbol + "_rms", unit, "RMS of " + what, Statistic::kRms, columns});
    t.push_back({symbol + "_max", unit, "peak of " + what, Statistic::kMax, columns});
  };
  both("Fsh", "N", "the shaking force |Fsh|", {"Fshx", "Fshy"});
  both("Msh", "N m", "the shaking moment |Msh|", {"Msh"});
  for (const Input& in : l.inputs) {
    const bool one = l.inputs.size() == 1;
    const std::string column = one ? "tau" : "tau_" + in.name;
    const bool angle = in.kind == Input::Kind::kAngle;
    both(column, angle ? "N m" : "N",
         std::string(angle ? "the drive torque" : "the drive force") +
             (one ? "" : " of " + in.name) + " |" + column + "|",
         {column});
  }
  for (int g : model.ground_nodes()) {
    const std::string name = "R" + l.nodes[static_cast<std::size_t>(g)].name;
    both(name, "N",
         "the bearing force |" + name + "| at ground node " +
             l.nodes[static_cast<std::size_t>(g)].name,
         {name + "x", name + "y"});
  }
  for (int s : model.frame_guides()) {
    const std::string name = "R" + l.sliders[static_cast<std::size_t>(s)].name;
    both(name, "N",
         "the guide force |" + name + "| of slider " + l.sliders[static_cast<std::size_t>(s)].name,
         {name + "x", name + "y"});
  }
  for (const BalanceShaft& b : l.shafts) {
    const std::string name = "R" + b.name;
    both(name, "N", "the bearing force |" + name + "| of balance shaft " + b.name,
         {name + "x", name + "y"});
  }
  for (const JointForce& j : model.joints()) {
    const std::string name = "F" + j.name;
    t.push_back({name + "_max",
                 "N",
                 "peak of the joint force |" + name + "|",
                 Statistic::kMax,
                 {name + "x", name + "y"}});
  }
  return t;
}

std::vector<double> metric_values(const std::vector<ColumnMetric>& metrics, const Series& table) {
  std::vector<double> out(metrics.size(), 0.0);
  const std::size_t rows = table.rows();
  if (rows == 0) return out;
  for (std::size_t k = 0; k < metrics.size(); ++k) {
    const ColumnMetric& m = metrics[k];
    std::vector<int> c;
    for (const std::string& name : m.columns) c.push_back(table.column(name));
    RmsAccumulator rms;
    double peak = 0;
    for (std::size_t i = 0; i < rows; ++i) {
      double x = 0;
      if (c.size() == 1) {
        x = std::abs(table.at(i, static_cast<std::size_t>(c[0])));
      } else {
        x = magnitude(table.at(i, static_cast<std::size_t>(c[0])),
                      table.at(i, static_cast<std::size_t>(c[1])));
      }
      if (m.statistic == Statistic::kRms) {
        rms.add(x);
      } else {
        peak = std::max(peak, x);
      }
    }
    out[k] = m.statistic == Statistic::kRms ? rms.rms() : peak;
  }
  return out;
}

}  // namespace bd::core::planar
