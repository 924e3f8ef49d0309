#pragma once
// The UDP datagrams of a pcap file, as a DatagramFeed.

#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "net/datagram_feed.hpp"

namespace featsense::slam::detail {

class PcapDatagramFeed final : public DatagramFeed {
 public:
  /// Opens the file; throws InputError where it cannot be read or is no pcap.
  explicit PcapDatagramFeed(const std::string& path);

  std::optional<UdpDatagram> next() override { return reader_->next(); }
  std::optional<std::string> problem() const override { return reader_->problem(); }
  std::vector<std::string> end_warnings() const override;
  const std::string& origin() const override { return path_; }

 private:
  std::string path_;
  std::vector<char> buffer_;
  std::unique_ptr<std::ifstream> stream_;
  std::unique_ptr<PcapUdpReader> reader_;  // reads stream_
};

}  // namespace featsense::slam::detail
