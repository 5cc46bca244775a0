// implemented by its owner; see core/simulate.hpp
#include "core/simulate.hpp"
