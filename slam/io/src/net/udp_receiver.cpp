#include "net/udp_receiver.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>

#include "featsense/slam/scan_source.hpp"

namespace featsense::slam::detail {
namespace {

/// The largest UDP payload over IPv4.
constexpr size_t kMaxPayload = 65507;
/// How often the receive thread and a waiting next() look at their stop flags.
constexpr int kPollMs = 100;
/// The socket's own buffer: about a second of an OS1-128 at 2048x10 (the kernel may cap it
/// at net.core.rmem_max).
constexpr int kSocketBufferBytes = 32 << 20;

int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

std::string address_text(const std::string& host, const std::vector<int>& ports) {
  std::string text = "udp://" + host + ":";
  for (size_t i = 0; i < ports.size(); ++i) text += (i > 0 ? "," : "") + std::to_string(ports[i]);
  return text;
}

}  // namespace

UdpReceiver::UdpReceiver(UdpListenSettings settings)
    : settings_(std::move(settings)), origin_(address_text(settings_.host, settings_.ports)) {
  in_addr address{};
  if (::inet_pton(AF_INET, settings_.host.c_str(), &address) != 1) {
    throw InputError(origin_ + ": '" + settings_.host + "' is not an IPv4 address");
  }
  if (settings_.ports.empty()) throw InputError(origin_ + ": no port to listen on");
  if (settings_.buffer_datagrams == 0) settings_.buffer_datagrams = 1;
  for (int port : settings_.ports) {
    if (port < 1 || port > 65535) {
      throw InputError(origin_ + ": port " + std::to_string(port) + " is not in 1 .. 65535");
    }
    const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    if (fd < 0) throw InputError(origin_ + ": cannot open a UDP socket: " + std::strerror(errno));
    sockets_.push_back(fd);
    ports_.push_back(static_cast<uint16_t>(port));
    const int size = kSocketBufferBytes;
    ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &size, sizeof size);  // best effort
    sockaddr_in local{};
    local.sin_family = AF_INET;
    local.sin_port = htons(static_cast<uint16_t>(port));
    local.sin_addr = address;
    if (::bind(fd, reinterpret_cast<const sockaddr*>(&local), sizeof local) != 0) {
      const std::string why = std::strerror(errno);
      for (int s : sockets_) ::close(s);
      throw InputError(origin_ + ": cannot listen on " + settings_.host + ":" +
                       std::to_string(port) + ": " + why +
                       (errno == EADDRINUSE ? " (another program receives there: a driver, "
                                              "another featsense?)"
                                            : ""));
    }
  }
  thread_ = std::thread([this] { receive_loop(); });
}

UdpReceiver::~UdpReceiver() {
  stopping_ = true;
  if (thread_.joinable()) thread_.join();
  for (int fd : sockets_) ::close(fd);
}

void UdpReceiver::receive_loop() {
  std::vector<pollfd> polled;
  for (int fd : sockets_) polled.push_back({fd, POLLIN, 0});
  std::vector<uint8_t> buffer(kMaxPayload + 1);
  while (!stopping_) {
    const int ready = ::poll(polled.data(), polled.size(), kPollMs);
    if (ready <= 0) continue;  // timeout, or a signal: look at the flag again
    for (size_t i = 0; i < polled.size(); ++i) {
      if (polled[i].revents & POLLIN) drain(polled[i].fd, ports_[i], buffer);
    }
  }
}

void UdpReceiver::drain(int socket, uint16_t port, std::vector<uint8_t>& buffer) {
  for (;;) {
    sockaddr_in from{};
    socklen_t from_size = sizeof from;
    const ssize_t n = ::recvfrom(socket, buffer.data(), buffer.size(), MSG_DONTWAIT | MSG_TRUNC,
                                 reinterpret_cast<sockaddr*>(&from), &from_size);
    if (n < 0) {
      if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) {
        std::lock_guard<std::mutex> lock(mutex_);
        ++stats_.receive_errors;
      }
      return;
    }
    const int64_t stamp = now_ns();
    std::lock_guard<std::mutex> lock(mutex_);
    ++stats_.received;
    if (static_cast<size_t>(n) > kMaxPayload) {
      ++stats_.truncated;
      continue;
    }
    if (buffer_.size() >= settings_.buffer_datagrams) {
      ++stats_.dropped_full;
      continue;
    }
    Received r;
    r.bytes.assign(buffer.begin(), buffer.begin() + n);
    r.timestamp_ns = stamp;
    r.source_port = ntohs(from.sin_port);
    r.destination_port = port;
    buffer_.push_back(std::move(r));
    arrived_.notify_one();
  }
}

std::optional<UdpDatagram> UdpReceiver::next() {
  if (ended_why_) return std::nullopt;
  std::unique_lock<std::mutex> lock(mutex_);
  auto idle_since = std::chrono::steady_clock::now();
  while (buffer_.empty()) {
    if (settings_.stop_requested && settings_.stop_requested()) {
      ended_why_ = "stopped";
      return std::nullopt;
    }
    if (settings_.idle_timeout_s > 0.0 &&
        std::chrono::duration<double>(std::chrono::steady_clock::now() - idle_since).count() >=
            settings_.idle_timeout_s) {
      ended_why_ = "no datagram for " + std::to_string(settings_.idle_timeout_s) + " s";
      return std::nullopt;
    }
    arrived_.wait_for(lock, std::chrono::milliseconds(kPollMs));
  }
  current_ = std::move(buffer_.front());
  buffer_.pop_front();
  UdpDatagram datagram;
  datagram.timestamp_ns = current_.timestamp_ns;
  datagram.source_port = current_.source_port;
  datagram.destination_port = current_.destination_port;
  datagram.payload = current_.bytes.data();
  datagram.size = current_.bytes.size();
  return datagram;
}

UdpReceiveStats UdpReceiver::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stats_;
}

std::vector<std::string> UdpReceiver::end_warnings() const {
  const UdpReceiveStats s = stats();
  std::vector<std::string> warnings;
  if (s.dropped_full > 0) {
    warnings.push_back(origin_ + ": " + std::to_string(s.dropped_full) + " of " +
                       std::to_string(s.received) + " datagrams dropped: the reader fell " +
                       std::to_string(settings_.buffer_datagrams) + " datagrams behind");
  }
  if (s.truncated > 0) {
    warnings.push_back(origin_ + ": " + std::to_string(s.truncated) +
                       " datagrams longer than a UDP payload can be; dropped");
  }
  if (s.receive_errors > 0) {
    warnings.push_back(origin_ + ": " + std::to_string(s.receive_errors) + " receive errors");
  }
  return warnings;
}

}  // namespace featsense::slam::detail
