#pragma once
/// Internal to bd_studies (yaml-cpp types): the loader's entry for a study file already held as a
/// YAML tree, and the path syntax of `sweep` parameters, shared by the loader (which checks each
/// path against the file) and point_study() (which sets the value at each path). Not for use
/// outside studies/*.cpp.
#include <yaml-cpp/yaml.h>

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "studies/study/study.hpp"

namespace bd::studies::internal {

/// Parses and checks a study given as a YAML tree exactly as parse_study() checks its text;
/// errors are reported at the tree's marks, so a tree loaded from a file's text and then edited
/// in place (scalars set, keys removed) still names places in that file. `source_name` names the
/// file in errors and in Study::source. A `sweep` section is checked, but its study_text is left
/// empty (parse_study() fills it).
/// @throws StudyError as parse_study().
Study parse_study_tree(const YAML::Node& root, const std::string& source_name);

/// One step of a sweep path: a map key, or a list index when `key` is empty.
struct PathStep {
  std::string key;
  std::size_t index{};
};

/// The steps of `path` (map keys of letters, digits, '_' and '-' joined by '.', a list element
/// by [i], e.g. "loads.crank.force[1]" -> key loads, key crank, key force, index 1), or nothing
/// when `path` does not follow that syntax. The first step is always a key.
std::optional<std::vector<PathStep>> parse_path(const std::string& path);

/// The node at `steps` in `root`, sharing its data with the tree (assigning to it edits `root`).
/// Precondition: every step exists (the loader checked the path against the same text).
YAML::Node node_at(YAML::Node root, const std::vector<PathStep>& steps);

}  // namespace bd::studies::internal
