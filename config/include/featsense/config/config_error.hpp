#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace featsense::config {

/// A configuration value or file that cannot be used; the message names the key and source.
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The candidate closest to `word` by edit distance, or "" when none is close enough to be
/// a plausible typo. Used for did-you-mean hints on keys, presets and subcommands.
std::string closest_match(const std::string& word, const std::vector<std::string>& candidates);

}  // namespace featsense::config
