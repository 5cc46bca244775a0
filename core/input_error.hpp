#pragma once
#include <stdexcept>
#include <string>

namespace bd {
/// A caller's or a study file's mistake (negative mass, zero length, unknown key). Thrown once,
/// where the value enters; the message names the quantity, the value, the unit and what was
/// expected, e.g. "coupler.mass must be > 0 kg, got -1.2".
class InputError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};
}  // namespace bd
