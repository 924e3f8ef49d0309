// How many malloc arenas the program's threads share.

#pragma once

namespace featsense::app {

/// glibc gives threads that allocate at once arenas of their own, up to 8 per core, and each
/// arena keeps what is freed in it for its next use. A run whose phases allocate on many
/// threads in turn (the mapping, then every tile's mesh and comparison) then holds the sum of
/// the arenas' peaks: on 16 cores `map --tiles` of the city's first km peaked at 2.47 GB
/// with the default arenas and at 1.59 GB with two, in the same time. The program keeps two
/// unless MALLOC_ARENA_MAX says otherwise. Not done by the library: the process's allocator
/// is its embedder's to set.
void limit_malloc_arenas();

}  // namespace featsense::app
