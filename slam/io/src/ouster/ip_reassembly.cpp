#include "ouster/ip_reassembly.hpp"

#include <algorithm>
#include <cstring>
#include <utility>

namespace featsense::slam::detail {

void IpReassembler::add_range(std::vector<std::pair<size_t, size_t>>& ranges, size_t begin,
                              size_t end) {
  ranges.emplace_back(begin, end);
  std::sort(ranges.begin(), ranges.end());
  std::vector<std::pair<size_t, size_t>> merged;
  merged.reserve(ranges.size());
  for (const auto& range : ranges) {
    if (!merged.empty() && range.first <= merged.back().second) {
      merged.back().second = std::max(merged.back().second, range.second);
    } else {
      merged.push_back(range);
    }
  }
  ranges = std::move(merged);
}

void IpReassembler::drop(size_t index) {
  pending_.erase(pending_.begin() + static_cast<std::ptrdiff_t>(index));
  ++dropped_;
}

void IpReassembler::drop_stale(int64_t now_ns) {
  for (size_t i = 0; i < pending_.size();) {
    // Capture clocks can step backwards; a datagram that far in the "future" is stale too.
    const int64_t age = now_ns - pending_[i].first_seen_ns;
    if (age > settings_.timeout_ns || age < -settings_.timeout_ns) {
      drop(i);
    } else {
      ++i;
    }
  }
}

const std::vector<uint8_t>* IpReassembler::add(const FragmentKey& key, size_t offset_bytes,
                                               bool more_fragments, const uint8_t* data,
                                               size_t size, int64_t timestamp_ns) {
  drop_stale(timestamp_ns);
  auto it = std::find_if(pending_.begin(), pending_.end(),
                         [&](const Pending& p) { return p.key == key; });
  if (it == pending_.end()) {
    if (pending_.size() >= settings_.max_pending) drop(0);
    Pending fresh;
    fresh.key = key;
    fresh.first_seen_ns = timestamp_ns;
    pending_.push_back(std::move(fresh));
    it = pending_.end() - 1;
  }
  const size_t index = static_cast<size_t>(it - pending_.begin());
  Pending& p = *it;
  const size_t end = offset_bytes + size;
  const bool too_long = end > kMaxPayloadBytes;
  // A fragment past the known end, a second "last" fragment that disagrees, or a last
  // fragment that ends before data already received all mean the datagram cannot be trusted.
  const bool beyond_end = p.total_known && end > p.total_bytes;
  const bool conflicting_end =
      !more_fragments && (p.total_known ? end != p.total_bytes : end < p.data.size());
  if (too_long || beyond_end || conflicting_end ||
      ++p.fragments > settings_.max_fragments_per_datagram) {
    drop(index);
    return nullptr;
  }
  if (!more_fragments) {
    p.total_known = true;
    p.total_bytes = end;
  }
  if (p.data.size() < end) p.data.resize(end);
  if (size > 0) std::memcpy(p.data.data() + offset_bytes, data, size);
  if (size > 0) add_range(p.ranges, offset_bytes, end);

  const bool complete = p.total_known && p.ranges.size() == 1 && p.ranges[0].first == 0 &&
                        p.ranges[0].second == p.total_bytes;
  if (!complete) return nullptr;
  completed_ = std::move(p.data);
  pending_.erase(pending_.begin() + static_cast<std::ptrdiff_t>(index));
  ++reassembled_;
  return &completed_;
}

}  // namespace featsense::slam::detail
