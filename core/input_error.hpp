#pragma once
/// Mistakes in the input, one idiom for the whole code base: a check returns or throws a
/// FieldError, which says which field of the checked object is wrong and what is wrong with it.
/// Callers that know where a field came from (the study loader knows each value's line and
/// column in the study file) locate the mistake from `field` and `index`, never from the text.
#include <optional>
#include <stdexcept>
#include <string>

namespace bd {

/// One problem with one field of an input.
struct FieldError {
  /// The field's path in the checked object, e.g. "coupler.mass", "scene.omega1",
  /// "counterweights", "max_evaluations"; empty when the problem is the object as a whole.
  std::string field;
  /// The element of a list field (objective term 2: field "objective", index 2); -1 for none.
  int index = -1;
  /// What is wrong, reading on from the field's name: "must be > 0 kg, got -1.2", or, after a
  /// colon, ": the original design's value is 0", or a sub-field of a list element,
  /// ".mass must be >= 0 kg, got -1". Starts with ':', ',' or '.' to be joined without a space.
  std::string message;

  /// The field (with "[index]") and the message as one line, e.g.
  /// "coupler.mass must be > 0 kg, got -1.2", "objective[2]: the original's Fsh_rms is 0".
  std::string text() const {
    return joined(field + (index >= 0 ? "[" + std::to_string(index) + "]" : ""));
  }
  /// `name` in place of the field and index, followed by the message (the study loader names
  /// the field by its path in the study file).
  std::string joined(const std::string& name) const {
    if (name.empty()) return message.rfind(": ", 0) == 0 ? message.substr(2) : message;
    if (message.empty()) return name;
    return name + (message[0] == ':' || message[0] == ',' || message[0] == '.' ? "" : " ") +
           message;
  }
};

/// What a validate() returns: empty when the object is valid, else its first problem.
using Problem = std::optional<FieldError>;

/// The problem's text(), or "" when there is none.
inline std::string problem_text(const Problem& problem) {
  return problem ? problem->text() : std::string();
}

/// A caller's or a study file's mistake (negative mass, zero length, unknown key). Thrown once,
/// where the value enters; the message names the quantity, the value, the unit and what was
/// expected, e.g. "coupler.mass must be > 0 kg, got -1.2". Thrown from a FieldError it carries
/// the field, so a caller can say where the value came from.
class InputError : public std::invalid_argument {
 public:
  explicit InputError(const std::string& message) : std::invalid_argument(message) {}
  explicit InputError(FieldError error)
      : std::invalid_argument(error.text()), field_(std::move(error)) {}
  /// The field the mistake is in, when the thrower said.
  const std::optional<FieldError>& field() const { return field_; }

 private:
  std::optional<FieldError> field_;
};

/// Throws InputError(*problem) when there is a problem.
inline void throw_if(const Problem& problem) {
  if (problem) throw InputError(*problem);
}

}  // namespace bd
