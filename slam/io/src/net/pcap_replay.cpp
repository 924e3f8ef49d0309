#include "featsense/slam/io/pcap_replay.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <optional>
#include <random>
#include <thread>

#include "featsense/slam/scan_source.hpp"
#include "net/pcap_datagram_feed.hpp"

namespace featsense::slam {
namespace {

using Clock = std::chrono::steady_clock;

/// Waits until `when`, asking `stop` about every 0.1 s; false where it was stopped.
bool wait_until(Clock::time_point when, const std::function<bool()>& stop) {
  for (;;) {
    if (stop && stop()) return false;
    const Clock::time_point now = Clock::now();
    if (now >= when) return true;
    std::this_thread::sleep_until(std::min(when, now + std::chrono::milliseconds(100)));
  }
}

class UdpSender {
 public:
  explicit UdpSender(const std::string& host)
      : fd_(::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0)) {
    if (fd_ < 0) throw InputError("cannot open a UDP socket to send with");
    if (::inet_pton(AF_INET, host.c_str(), &address_) != 1) {
      ::close(fd_);
      throw InputError("replay: '" + host + "' is not an IPv4 address");
    }
  }
  ~UdpSender() { ::close(fd_); }
  UdpSender(const UdpSender&) = delete;
  UdpSender& operator=(const UdpSender&) = delete;

  bool send(const uint8_t* data, size_t size, int port) const {
    sockaddr_in to{};
    to.sin_family = AF_INET;
    to.sin_port = htons(static_cast<uint16_t>(port));
    to.sin_addr = address_;
    return ::sendto(fd_, data, size, 0, reinterpret_cast<const sockaddr*>(&to), sizeof to) ==
           static_cast<ssize_t>(size);
  }

 private:
  int fd_;
  in_addr address_{};
};

void check(const ReplaySettings& s) {
  if (!(s.rate > 0.0) || !std::isfinite(s.rate) || s.rate > 1000.0) {
    throw InputError("replay: --rate must be in (0, 1000], not " + std::to_string(s.rate));
  }
  if (!(s.drop_fraction >= 0.0 && s.drop_fraction < 1.0)) {
    throw InputError("replay: --drop must be in [0, 1), not " + std::to_string(s.drop_fraction));
  }
  for (const auto& [from, to] : s.ports) {
    if (from < 1 || from > 65535 || to < 1 || to > 65535) {
      throw InputError("replay: ports must be in 1 .. 65535 (" + std::to_string(from) + ":" +
                       std::to_string(to) + ")");
    }
  }
}

}  // namespace

ReplayResult replay_pcap(const std::string& path, const ReplaySettings& settings) {
  check(settings);
  UdpSender sender(settings.host);
  std::mt19937_64 random(settings.seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  ReplayResult result;
  const Clock::time_point start = Clock::now();
  Clock::time_point last_progress = start;
  // Each pass starts where the last ended, one mean datagram gap later.
  double pass_offset_s = 0.0;
  for (bool more = true; more;) {
    detail::PcapDatagramFeed feed(path);
    std::optional<int64_t> first_ns;
    int64_t last_ns = 0;
    size_t in_pass = 0;
    while (const std::optional<detail::UdpDatagram> datagram = feed.next()) {
      if (!first_ns) first_ns = datagram->timestamp_ns;
      last_ns = datagram->timestamp_ns;
      ++in_pass;
      const double at_s = pass_offset_s + 1e-9 * static_cast<double>(last_ns - *first_ns);
      const auto when = start + std::chrono::duration_cast<Clock::duration>(
                                    std::chrono::duration<double>(at_s / settings.rate));
      if (!wait_until(when, settings.stop_requested)) {
        more = false;
        break;
      }
      if (settings.drop_fraction > 0.0 && uniform(random) < settings.drop_fraction) {
        ++result.dropped;
        continue;
      }
      const auto mapped = settings.ports.find(datagram->destination_port);
      const int port = mapped != settings.ports.end() ? mapped->second : datagram->destination_port;
      if (sender.send(datagram->payload, datagram->size, port)) {
        ++result.sent;
        result.bytes += datagram->size;
      } else {
        ++result.failed;
      }
      if (settings.progress && Clock::now() - last_progress > std::chrono::milliseconds(200)) {
        last_progress = Clock::now();
        settings.progress(result.sent);
      }
    }
    if (!first_ns) {
      throw InputError(path + ": no UDP datagram to replay" +
                       (feed.problem() ? " (" + *feed.problem() + ")" : std::string()));
    }
    const double span_s = 1e-9 * static_cast<double>(last_ns - *first_ns);
    result.recording_seconds = span_s;
    ++result.passes;
    pass_offset_s += span_s + (in_pass > 1 ? span_s / static_cast<double>(in_pass - 1) : 0.0);
    more = more && settings.loop;
  }
  result.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  if (settings.progress) settings.progress(result.sent);
  return result;
}

}  // namespace featsense::slam
