#pragma once
// An Ouster sensor's metadata JSON from its HTTP API, for `featsense live` without --meta.

#include <string>

namespace featsense::app {

/// GET http://ADDRESS/api/v1/sensor/metadata (ADDRESS: host or host:port), the body checked
/// to be a JSON object. Throws slam::InputError naming the URL and what went wrong (no
/// answer within `timeout_s`, an HTTP status, a body that is no JSON object).
std::string fetch_ouster_metadata(const std::string& address, double timeout_s = 5.0);

}  // namespace featsense::app
