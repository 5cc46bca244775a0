#pragma once
/// Writing a study back as a study file (the inverse of parse_study, without a balance section).
#include <string>

#include "studies/study/study.hpp"

namespace bd::studies {

/// A complete, runnable study file for `study`: name, linkage (each link as {length, mass, e, f,
/// inertia}, counter_rotations when the model has any, and, when the study has counterweight
/// parts, the links without them and a counterweights section), every load, the scene with all
/// its keys, method and tolerance. Numbers are written in their shortest exact form, so
/// parse_study() of the text gives back the same model, scene and options bit for bit. A
/// balance or optimize section is never written.
/// `header` (may be empty) is written first as `# ` comment lines, one per line of it.
std::string study_yaml(const Study& study, const std::string& header);

}  // namespace bd::studies
