#pragma once
/// One alias for an expected-or-error value (GCC 12 has no std::expected; Debian's
/// libexpected-dev provides tl::expected with the same interface).
#include <tl/expected.hpp>

namespace bd {
template <class T, class E>
using Expected = tl::expected<T, E>;
/// tl::unexpected under our name. A class with its own deduction guide rather than an alias
/// template, so that `Unexpected(error)` also compiles with clang 14 (the fuzz and sanitizer
/// builds, .ci/fuzz), which does not deduce through alias templates (C++20's P1814).
template <class E>
class Unexpected : public tl::unexpected<E> {
 public:
  using tl::unexpected<E>::unexpected;
};
template <class E>
Unexpected(E) -> Unexpected<E>;
}  // namespace bd
