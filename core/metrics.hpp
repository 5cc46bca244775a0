#pragma once
/// What the metric tables of every linkage type share (core/fourbar/metrics.hpp for the
/// four-bar, core/planar/metrics.hpp for general planar linkages): each metric summarises one
/// magnitude over a run's samples, as its RMS or its peak. Every table lists, per quantity, the
/// RMS and then the peak.
namespace bd::core {

/// How the samples' magnitudes become one number.
enum class Statistic {
  kRms,  // sqrt(Σ x² / n)
  kMax,  // max x
};

}  // namespace bd::core
