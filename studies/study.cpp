#include "studies/study.hpp"

#include <string_view>

namespace bd::studies {

namespace {
// every formulation core implements; extend when core::Formulation grows
constexpr core::Formulation kAvailableFormulations[] = {core::Formulation::kMassMatrix};
}  // namespace

const char* scene_type(const Scene& scene) {
  return std::holds_alternative<core::FreeScene>(scene) ? "free" : "driven";
}

std::optional<core::Formulation> available_formulation(const std::string& name) {
  for (core::Formulation f : kAvailableFormulations) {
    if (name == core::to_string(f)) return f;
  }
  return std::nullopt;
}

std::string Study::method_name() const {
  return formulation ? std::string(core::to_string(*formulation)) : std::string("auto");
}

MethodChoice choose_method(const Study& study) {
  MethodChoice choice;
  if (study.formulation) {
    choice.formulation = *study.formulation;
    choice.reason = "requested in the study file";
  } else {
    // only one formulation exists so far, and it is exact
    choice.formulation = core::Formulation::kMassMatrix;
    choice.reason = "the only formulation available; exact, constant 4x4 mass matrix";
  }
  if (std::holds_alternative<core::DrivenScene>(study.scene)) {
    choice.reason += "; no integrator: kinetostatics per sample";
  }
  return choice;
}

}  // namespace bd::studies
