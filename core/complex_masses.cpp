// implemented by its owner; see core/complex_masses.hpp
#include "core/complex_masses.hpp"
