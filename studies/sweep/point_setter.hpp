#pragma once
/// Internal to studies/sweep: the study at a sweep point built from the loaded study by setting
/// the swept values in its model (a four-bar's links, frame, loads and scene), instead of
/// reading the study file's YAML tree again (point_study()). Only values whose field the setter
/// knows and whose checks it repeats go this way; any other sweep, and any point where a check
/// fails, goes through point_study(), so a failing point's message is the loader's own.
#include <optional>
#include <span>
#include <vector>

#include "studies/study/study.hpp"

namespace bd::studies::detail {

class PointSetter {
 public:
  /// The setter of `base`'s sweep, or nothing when some parameter has no setter (a planar study,
  /// an optimize section, a path the setter does not know, a sibling value the file gives with a
  /// unit).
  static std::optional<PointSetter> make(const Study& base);

  /// The loader is the referee: whether the study apply() builds at `values` is, in every bit
  /// the row is computed from, point_study()'s (undecided when either refuses the point).
  enum class Verdict { kSame, kDiffers, kUndecided };
  Verdict check(const Study& base, std::span<const double> values) const;

  /// The study at `values`: base with the values set and checked as the loader checks them
  /// (core::make_fourbar(), s >= 0, a driven speed != 0, a duration > 0, assembly at the
  /// initial crank angle, a driven crank that turns fully, the balance synthesis), or nothing
  /// when a check fails (then point_study() says why, at its place in the file).
  std::optional<Study> apply(const Study& base, std::span<const double> values) const;

  enum class Field {
    kFrame, kLength, kMass, kInertia, kE, kF, kS, kSigma,  // linkage (link fields on `link`)
    kForce, kMoment, kGravity,                             // loads (`link`, `index`)
    kTheta1, kOmega1, kDuration,                           // scene
  };
  struct Target {
    Field field{};
    int link = 0;   // 1 crank, 2 coupler, 3 rocker
    int index = 0;  // a vector's element
  };

 private:
  std::vector<Target> targets_;  // one per parameter
  // each link's centre of mass as the file states it, when polar (s [m], sigma [rad]); the
  // setter rebuilds e, f from them as the loader does
  struct Polar {
    bool given = false;
    double s{}, sigma{};
  };
  Polar polar_[3];
};

/// The study at a point of `base`'s sweep: from the setter when it applies (made once per thread
/// and sweep, and held to point_study() at the first point it can be), else point_study().
/// @throws StudyError as point_study().
Study sweep_point_study(const Study& base, std::span<const double> values);

}  // namespace bd::studies::detail
