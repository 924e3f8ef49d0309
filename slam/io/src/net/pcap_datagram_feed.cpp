#include "net/pcap_datagram_feed.hpp"

#include "featsense/slam/scan_source.hpp"

namespace featsense::slam::detail {

PcapDatagramFeed::PcapDatagramFeed(const std::string& path)
    : path_(path), stream_(std::make_unique<std::ifstream>()) {
  // A large stream buffer: a lidar packet is 8 to 25 KB, the default buffer far smaller.
  buffer_.resize(1 << 20);
  stream_->rdbuf()->pubsetbuf(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
  stream_->open(path, std::ios::binary);
  if (!*stream_) throw InputError(path + ": cannot open (missing or permission denied?)");
  reader_ = std::make_unique<PcapUdpReader>(*stream_, path);
}

std::vector<std::string> PcapDatagramFeed::end_warnings() const {
  std::vector<std::string> warnings;
  if (reader_->problem()) warnings.push_back(*reader_->problem());
  if (reader_->stats().malformed > 0) {
    warnings.push_back(path_ + ": " + std::to_string(reader_->stats().malformed) +
                       " IP/UDP packets were damaged or cut short by the capture's snap "
                       "length; skipped");
  }
  if (reader_->incomplete_datagrams() > 0) {
    warnings.push_back(path_ + ": " + std::to_string(reader_->incomplete_datagrams()) +
                       " fragmented IP datagrams could not be reassembled (fragments missing)");
  }
  return warnings;
}

}  // namespace featsense::slam::detail
