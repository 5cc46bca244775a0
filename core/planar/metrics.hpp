#pragma once
/// The metrics of a planar linkage's run, built for its model as the four-bar's table is
/// (core/metrics.hpp): per quantity its RMS over the samples, then its peak, in this order:
/// Fsh, Msh, the drive efforts (tau, or tau_<input> with several inputs), the reaction of every
/// ground node and frame guide (R<name>); then the peak of every joint force (F<joint>_max).
/// Each is the magnitude of one column (Msh, tau) or of an x, y pair of columns.
#include <string>
#include <vector>

#include "core/metrics.hpp"
#include "core/planar/dynamics.hpp"
#include "core/series.hpp"

namespace bd::core::planar {

struct ColumnMetric {
  std::string name;   // "Fsh_rms", "RA0_max", "FA1_max"
  std::string unit;   // "N", "N m"
  std::string words;  // "RMS of the shaking force |Fsh|"
  Statistic statistic = Statistic::kRms;
  std::vector<std::string> columns;  // one column, or the x and y columns of a vector
};

/// The model's metric table.
std::vector<ColumnMetric> metric_table(const Model& model);

/// The table's values over the rows of `table` (0 for a table without rows).
std::vector<double> metric_values(const std::vector<ColumnMetric>& metrics, const Series& table);

}  // namespace bd::core::planar
