#pragma once
/// Running a study: simulate its scene, then write timeseries.csv and summary.json
/// (DESIGN.md "Outputs (v1 contract)").
#include <filesystem>
#include <string>

#include "core/metrics.hpp"
#include "core/simulate.hpp"
#include "studies/study.hpp"

namespace bd::studies {

/// The header line of timeseries.csv (without the newline).
inline constexpr const char* kTimeseriesHeader =
    "t,theta1,theta2,theta3,omega1,omega2,omega3,alpha1,alpha2,alpha3,RA0x,RA0y,RA3x,RA3y,Fshx,"
    "Fshy,Msh,tau";

/// What a run did and where its files are.
struct RunResult {
  MethodChoice method;               // formulation used, and why
  core::Trajectory trajectory;       // every sample computed, and the simulation's status
  core::Metrics metrics;             // over the samples computed
  std::filesystem::path timeseries;  // out_dir/timeseries.csv
  std::filesystem::path summary;     // out_dir/summary.json
  /// True when the simulation ran to the end (trajectory.ok()).
  bool ok() const { return trajectory.ok(); }
};

/// Simulates the study's scene (core::simulate_free or core::simulate_driven) and writes
/// `timeseries.csv` and `summary.json` into out_dir, creating out_dir when needed (and only after
/// the simulation, so an invalid study creates nothing). Each file is written to a temporary
/// file in out_dir and renamed into place, so no half-written output is ever left. When the
/// simulation stops early, every sample computed so far is written and summary.json records the
/// status and message; the result's ok() is then false.
/// @throws bd::InputError if the scene or options are invalid (core's checks).
/// @throws std::runtime_error if an output file cannot be written (the message names it).
RunResult run_study(const Study& study, const std::filesystem::path& out_dir);

/// Writes the samples as timeseries.csv content (header, one row per sample, "%.17g").
/// @throws std::runtime_error if the file cannot be written.
void write_timeseries(const core::Trajectory& trajectory, const std::filesystem::path& file);

/// The summary.json text of a run (UTF-8, ends in a newline).
std::string summary_json(const Study& study, const RunResult& result);

/// `text` as a JSON string literal, quotes included, with every character that needs it escaped.
std::string json_string(const std::string& text);

}  // namespace bd::studies
