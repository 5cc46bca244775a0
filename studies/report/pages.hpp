#pragma once
/// Internal to studies/report/: the study page of each linkage type, and its linkage tables
/// (report.cpp picks by the study's type).
#include <filesystem>
#include <string>

#include "core/fourbar/model.hpp"
#include "core/planar/model.hpp"
#include "studies/report/report_support.hpp"
#include "studies/study/study.hpp"

namespace bd::studies::report_support {

/// A four-bar's page: its linkage, metrics, comparison, charts (angles, reactions, hodograph,
/// shaking moment, drive torque and bearing loads, the linkage with its principal points), the
/// balanced or optimised design and the Pareto front.
std::string fourbar_report_html(const Study& study, const std::filesystem::path& dir,
                                const std::string& gnuplot, const Json& summary);
/// A planar linkage's page: its nodes, links, sliders and inputs, metrics, charts (angles,
/// support reactions, hodograph, shaking moment, drive efforts, joint forces, the linkage drawn
/// at a few samples).
std::string planar_report_html(const Study& study, const std::filesystem::path& dir,
                               const std::string& gnuplot, const Json& summary);

std::string fourbar_linkage_tables(const core::FourBar& model);
std::string planar_linkage_tables(const core::planar::Linkage& linkage);

}  // namespace bd::studies::report_support
