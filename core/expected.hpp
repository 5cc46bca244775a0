#pragma once
/// One alias for an expected-or-error value (GCC 12 has no std::expected; Debian's
/// libexpected-dev provides tl::expected with the same interface).
#include <tl/expected.hpp>

namespace bd {
template <class T, class E>
using Expected = tl::expected<T, E>;
template <class E>
using Unexpected = tl::unexpected<E>;
}  // namespace bd
