#pragma once
/// The `sweep:` section of a study (docs/study-format.md "sweep"): which study values to vary,
/// by their path in the study file, and over which design of points. Pure data; the points and
/// the study of each point come from studies/sweep.hpp, the run from run_sweep().
#include <cstdint>
#include <string>
#include <vector>

namespace bd::studies {

/// How the points are laid out.
enum class SweepDesign {
  kGrid,            // the Cartesian product of every parameter's values (first varies slowest)
  kRandom,          // `points` independent uniform draws in the parameters' box
  kLatinHypercube,  // `points` draws, each parameter's range cut into `points` equal strata,
                    // one draw per stratum, strata paired by random permutations
};
/// "grid", "random", "lhs".
const char* to_string(SweepDesign design);

/// One varied value.
struct SweepParameter {
  /// Where the value is in the study file: map keys joined by '.', a vector element by [i],
  /// e.g. "linkage.coupler.mass", "scene.omega1", "loads.crank.force[1]". It names a number the
  /// study file states (a value left at its default must be written in the file to be swept).
  std::string path;
  /// Grid: the values, in order (given as a list, or from `from` to `to` in `count` steps).
  /// Random and LHS: empty.
  std::vector<double> values;
  double from{}, to{};     // the range (random, LHS; and grid when given by from/to/count)
  bool log_scale = false;  // from/to spaced (grid) or drawn (random, LHS) uniformly in log;
                           // then 0 < from < to
  int line{}, column{};    // where the parameter is given in the study file (1-based)
};

/// The study file's `sweep:` section, defaults in place.
struct SweepRequest {
  SweepDesign design = SweepDesign::kGrid;
  std::vector<SweepParameter> parameters;  // >= 1, paths distinct
  int points{};            // random and LHS: how many (>= 1); grid: the product of the counts
  std::uint64_t seed = 1;  // random and LHS: the same seed gives the same points everywhere
  int threads = 0;         // parallel runs; 0: one per core
  /// The study file's text as loaded: each point's study is this text with the parameters set
  /// (point_study()), so errors at a point name places in the user's file.
  std::string study_text;
};

}  // namespace bd::studies
