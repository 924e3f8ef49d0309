#include "malloc_arenas.hpp"

#include <cstdlib>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace featsense::app {

void limit_malloc_arenas() {
#if defined(__GLIBC__)
  // The variable is read by glibc itself at the first allocation; a value given there wins.
  if (std::getenv("MALLOC_ARENA_MAX") == nullptr) mallopt(M_ARENA_MAX, 2);
#endif
}

}  // namespace featsense::app
