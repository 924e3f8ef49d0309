#pragma once
// Sending datagrams to a live source over the loopback interface, for its tests.

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <thread>
#include <vector>

namespace featsense::test {

/// A UDP port no socket holds now (the kernel's pick for port 0).
inline int free_udp_port() {
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ::bind(fd, reinterpret_cast<const sockaddr*>(&a), sizeof a);
  socklen_t size = sizeof a;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &size);
  ::close(fd);
  return ntohs(a.sin_port);
}

struct Outgoing {
  int port = 0;
  std::vector<uint8_t> bytes;
};

/// Sends each datagram to 127.0.0.1, `gap` apart (the receiver's socket buffer may be as
/// small as the kernel's default: a burst of megabytes would overflow it).
inline void send_all(const std::vector<Outgoing>& datagrams, std::chrono::microseconds gap) {
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  for (const Outgoing& d : datagrams) {
    sockaddr_in to{};
    to.sin_family = AF_INET;
    to.sin_port = htons(static_cast<uint16_t>(d.port));
    to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ::sendto(fd, d.bytes.data(), d.bytes.size(), 0, reinterpret_cast<const sockaddr*>(&to),
             sizeof to);
    std::this_thread::sleep_for(gap);
  }
  ::close(fd);
}

/// Sends each datagram when its recorded time (ns, any epoch) comes, counted from the first:
/// the sensor's own pace.
inline void send_paced(const std::vector<Outgoing>& datagrams,
                       const std::vector<int64_t>& times_ns) {
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  const auto start = std::chrono::steady_clock::now();
  for (size_t i = 0; i < datagrams.size(); ++i) {
    std::this_thread::sleep_until(start + std::chrono::nanoseconds(times_ns[i] - times_ns[0]));
    sockaddr_in to{};
    to.sin_family = AF_INET;
    to.sin_port = htons(static_cast<uint16_t>(datagrams[i].port));
    to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ::sendto(fd, datagrams[i].bytes.data(), datagrams[i].bytes.size(), 0,
             reinterpret_cast<const sockaddr*>(&to), sizeof to);
  }
  ::close(fd);
}

}  // namespace featsense::test
