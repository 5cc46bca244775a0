// implemented by its owner; see core/metrics.hpp
#include "core/metrics.hpp"
