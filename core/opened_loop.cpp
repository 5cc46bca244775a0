// implemented by its owner; see core/opened_loop.hpp
#include "core/opened_loop.hpp"
