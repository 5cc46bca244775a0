#pragma once
/// Internal to studies/study/: one reader per section of a study file, on the shared map reader
/// (yaml_reader.hpp). load_study.cpp reads the top level and hands each section to its reader:
/// - fourbar_section.cpp: linkage (type: fourbar), loads and scene of a four-bar;
/// - planar_section.cpp: linkage (type: planar), loads and scene of a general planar linkage;
/// - balance_section.cpp: the balance section (a four-bar's or a planar linkage's);
/// - optimize_section.cpp: the optimize section (a four-bar's or a planar linkage's);
/// - sweep_section.cpp: the sweep section, its paths checked against the file's tree.
#include <memory>
#include <optional>

#include "studies/study/study.hpp"
#include "studies/study/yaml_reader.hpp"

namespace bd::studies::detail {

/// The links that can carry a four-bar's counterweight or counter-rotation; pivots A0 and A3.
inline constexpr const char* kSides[] = {"crank", "rocker"};

/// A four-bar's linkage, loads and scene.
class FourBarSection {
 public:
  explicit FourBarSection(const Reporter& r);
  ~FourBarSection();
  /// The linkage and its loads, checked by core::make_fourbar() (a complaint at the value's
  /// place; `loads` may be null).
  core::FourBar read(const MapReader::Entry& linkage, const MapReader::Entry* loads);
  /// The scene, and the linkage assembled at its initial crank angle.
  Scene read_scene(const MapReader::Entry& scene, const core::FourBar& model);
  /// The counterweight parts read() merged into the links, and the linkage without them; empty
  /// when linkage.counterweights is absent.
  std::optional<LinkageParts> parts() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

/// A general planar linkage's linkage, loads and scene.
class PlanarSection {
 public:
  explicit PlanarSection(const Reporter& r);
  ~PlanarSection();
  /// The linkage (nodes, links, point masses, sliders, springs, inputs) and its loads, checked by
  /// core::planar::make_linkage(), its mobility and its assembly (a complaint at the place of
  /// the item it names; `loads` may be null).
  core::planar::Linkage read(const MapReader::Entry& linkage, const MapReader::Entry* loads);
  /// The scene, checked against the linkage's inputs.
  Scene read_scene(const MapReader::Entry& scene, const core::planar::Linkage& linkage);
  /// As FourBarSection::parts().
  std::optional<LinkageParts> parts() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

/// A counter-rotation shaft position [x, y] on the four-bar's frame, away from its link's pivot
/// (side 0: the crank's, at A0; 1: the rocker's, at A3).
Vec2 read_shaft(const Reporter& r, const MapReader::Entry& at, const std::string& path, int side,
                double frame);
/// `shape: point | disc` of a counterweight at `path`.
balance::CounterweightShape read_shape(const Reporter& r, const MapReader::Entry& shape,
                                       const std::string& path);

/// A counterweight given as a part of its link (linkage.counterweights.<link> at `path`, the map
/// `m`, its keys checked by the caller): mass >= 0 [kg], at [x, y] [m] in the link's axes from
/// its pivot, inertia >= 0 about its own centre [kg m^2] (default 0, a point mass).
balance::Counterweight read_counterweight_part(const Reporter& r, const MapReader& m,
                                              const std::string& path);

/// The balance section, synthesised (a synthesis that is not possible is reported at the key
/// that asked for it).
balance::BalancedDesign read_balance(const Reporter& r, const MapReader::Entry& e,
                                     const core::FourBar& model);
/// A planar linkage's balance section: the links to carry counterweights (default: those that
/// turn about a ground node), checked against the linkage.
balance::planar::BalanceRequest read_planar_balance(const Reporter& r, const MapReader::Entry& e,
                                                    const core::planar::Linkage& linkage);
/// A four-bar's optimize section, checked by the optimize layer.
OptimizeRequest read_optimize(const Reporter& r, const MapReader::Entry& e, const Study& study);
/// A planar linkage's optimize section, checked by the optimize layer.
PlanarOptimizeRequest read_planar_optimize(const Reporter& r, const MapReader::Entry& e,
                                           const Study& study);
/// The sweep section; each path is checked against `root`, the study file's tree.
SweepRequest read_sweep(const Reporter& r, const MapReader::Entry& e, const YAML::Node& root);

}  // namespace bd::studies::detail
