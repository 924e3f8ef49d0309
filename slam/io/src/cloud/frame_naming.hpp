#pragma once
// What the names of scan files say: their order, and time stamps written into them.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace featsense::slam::cloud {

/// Natural order: runs of digits compare as numbers ("2" < "10"), the rest as text; names
/// equal as numbers compare by their text (so "01" and "1" still have an order).
bool natural_less(std::string_view a, std::string_view b);

/// The time stamp (ns since 1970) a file's base name holds, if it looks like one: trailing
/// digits that are nanoseconds in 1973 .. 2103 (1e17 .. 4.2e18, e.g. `vlp16_1673400472138016708`),
/// or trailing seconds with a fraction (`1673400472.138016708`, 1e8 .. 4.2e9 s). Frame numbers
/// such as `000042` are not stamps.
std::optional<int64_t> stamp_from_name(std::string_view stem);

}  // namespace featsense::slam::cloud
