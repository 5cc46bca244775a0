// implemented by its owner; see core/energy.hpp
#include "core/energy.hpp"
