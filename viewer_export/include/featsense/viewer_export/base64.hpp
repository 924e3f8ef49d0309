#pragma once
// Base64 (RFC 4648, with padding): how report.html carries its pictures inside itself.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace featsense::viewer_export {

/// The bytes in base64's standard alphabet, padded with '=' to a multiple of 4 characters.
std::string base64_encode(std::string_view bytes);
std::string base64_encode(const std::vector<uint8_t>& bytes);

}  // namespace featsense::viewer_export
