#include "ouster_metadata_fetch.hpp"

// Eigen (through scan_source.hpp) before cpp-httplib: the other order breaks Eigen's
// product kernels' declarations.
#include "featsense/slam/scan_source.hpp"

// clang-format off
#include <httplib.h>
// clang-format on
#include <nlohmann/json.hpp>

#include <cmath>

namespace featsense::app {

std::string fetch_ouster_metadata(const std::string& address, double timeout_s) {
  constexpr const char* kPath = "/api/v1/sensor/metadata";
  const std::string url = "http://" + address + kPath;
  httplib::Client client("http://" + address);
  const auto seconds = static_cast<time_t>(std::floor(timeout_s));
  const auto microseconds = static_cast<time_t>((timeout_s - std::floor(timeout_s)) * 1e6);
  client.set_connection_timeout(seconds, microseconds);
  client.set_read_timeout(seconds, microseconds);
  const httplib::Result answer = client.Get(kPath);
  if (!answer) {
    throw slam::InputError(url + ": no answer (" + httplib::to_string(answer.error()) +
                           "); is the sensor's address right and the sensor on? Or pass its "
                           "metadata with --meta FILE");
  }
  if (answer->status != 200) {
    throw slam::InputError(url + ": HTTP status " + std::to_string(answer->status) +
                           " (an Ouster sensor of firmware 2.x or later serves its metadata "
                           "there); pass it with --meta FILE");
  }
  const nlohmann::json parsed = nlohmann::json::parse(answer->body, nullptr, false);
  if (parsed.is_discarded() || !parsed.is_object()) {
    throw slam::InputError(url + ": the answer is not a JSON object (" +
                           std::to_string(answer->body.size()) + " bytes)");
  }
  return answer->body;
}

}  // namespace featsense::app
