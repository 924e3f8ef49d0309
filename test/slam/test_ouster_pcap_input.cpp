// open_ouster_pcap on rewritten and damaged copies of the OS1-128 recording: cut files, garbage,
// wrong metadata, IP-fragmented packets, other ports and pcap variants, and how the metadata
// file is found.
//
// Policy checked here: a capture that yields no frame at all (no lidar packet of the size the
// metadata implies, or cut before the first one) is an InputError naming the sizes it did see;
// a capture cut later gives the frames before the cut plus a counted warning.

#include <gtest/gtest.h>

#include <set>

#include "common/test_data.hpp"
#include "featsense/slam/io/readers.hpp"
#include "pcap_test_util.hpp"

namespace featsense::slam {
namespace {

namespace fs = std::filesystem;
using test::CapturedFrame;

constexpr const char* kOs1Pcap = "ouster/OS-1-128_v2.3.0_1024x10_lb_n3.pcap";
constexpr const char* kOs1Json = "ouster/OS-1-128_v2.3.0_1024x10.json";
constexpr size_t kLidarFrameBytes = 14 + 20 + 8 + 8448;  // Ethernet + IPv4 + UDP + payload

struct ReadResult {
  std::vector<Scan> scans;
  ReadStats stats;
};

ReadResult read_pcap(const fs::path& pcap, const fs::path& json) {
  SourceOptions options;
  options.meta_path = json.string();
  std::unique_ptr<ScanSource> source = open_ouster_pcap(pcap.string(), options);
  ReadResult result;
  while (std::optional<Scan> scan = source->next()) result.scans.push_back(std::move(*scan));
  result.stats = source->stats();
  return result;
}

std::string error_reading(const fs::path& pcap, const fs::path& json) {
  try {
    read_pcap(pcap, json);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

fs::path write_scratch(const std::string& test_name, const std::string& bytes) {
  const fs::path path = test::scratch_dir(test_name) / "capture.pcap";
  test::write_file(path, bytes);
  return path;
}

void expect_identical(const std::vector<Scan>& a, const std::vector<Scan>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].stamp_ns, b[k].stamp_ns);
    EXPECT_EQ(a[k].valid, b[k].valid);
    EXPECT_EQ(a[k].xyz, b[k].xyz);
    EXPECT_EQ(a[k].range_m, b[k].range_m);
    EXPECT_EQ(a[k].time_offset_s, b[k].time_offset_s);
    ASSERT_EQ(a[k].channels.size(), b[k].channels.size());
    for (size_t c = 0; c < a[k].channels.size(); ++c) {
      EXPECT_EQ(a[k].channels[c].name, b[k].channels[c].name);
      EXPECT_EQ(a[k].channels[c].values, b[k].channels[c].values);
    }
  }
}

/// Frame ids (bytes 2..3 of the lidar payload) of the lidar packets in `frames`.
std::set<int> frame_ids(const std::vector<CapturedFrame>& frames) {
  std::set<int> ids;
  for (const CapturedFrame& f : frames) {
    if (f.bytes.size() == kLidarFrameBytes) ids.insert(f.bytes[44] | (f.bytes[45] << 8));
  }
  return ids;
}

TEST(OusterPcapInput, CutFiles) {
  FEATSENSE_SHARED_FILE(pcap, kOs1Pcap);
  FEATSENSE_SHARED_FILE(json, kOs1Json);
  const std::string bytes = test::read_file(pcap);
  const std::vector<CapturedFrame> frames = test::read_pcap_frames(bytes);

  // Inside the global header: not a pcap at all.
  for (const size_t cut : {0, 3, 10, 23}) {
    const std::string message = error_reading(write_scratch("cut", bytes.substr(0, cut)), json);
    EXPECT_NE(message.find("capture.pcap"), std::string::npos) << cut << ": " << message;
  }
  // The header alone, or cut inside the first record: no frame, an error that says why.
  for (const size_t cut : {24, 30, 24 + 16 + 100}) {
    const std::string message = error_reading(write_scratch("cut", bytes.substr(0, cut)), json);
    EXPECT_NE(message.find("no lidar packets of 8448 bytes"), std::string::npos) << message;
  }
  // Cut inside later records: the frames begun before the cut, and a warning about it.
  size_t record_start = 24;
  for (size_t k = 0; k < frames.size(); ++k) {
    const size_t record_bytes = 16 + frames[k].bytes.size();
    if (k == 50 || k == 100 || k == 150 || k + 1 == frames.size()) {
      for (const size_t into : {size_t{7}, size_t{16 + 1000}}) {
        const size_t cut = record_start + std::min(into, record_bytes - 1);
        SCOPED_TRACE("cut at " + std::to_string(cut));
        const std::vector<CapturedFrame> kept(frames.begin(),
                                              frames.begin() + static_cast<std::ptrdiff_t>(k));
        const ReadResult result = read_pcap(write_scratch("cut", bytes.substr(0, cut)), json);
        EXPECT_EQ(result.scans.size(), frame_ids(kept).size());
        ASSERT_GE(result.stats.warning_count, 1u);
        EXPECT_NE(result.stats.warnings[0].find("truncated record"), std::string::npos)
            << result.stats.warnings[0];
        EXPECT_NE(result.stats.warnings[0].find("offset " + std::to_string(record_start)),
                  std::string::npos)
            << result.stats.warnings[0];
      }
    }
    record_start += record_bytes;
  }
}

TEST(OusterPcapInput, IncompleteLastFrameIsWarnedAbout) {
  FEATSENSE_SHARED_FILE(pcap, kOs1Pcap);
  FEATSENSE_SHARED_FILE(json, kOs1Json);
  std::vector<CapturedFrame> frames = test::read_pcap_frames(test::read_file(pcap));
  // Drop the last 20 records (lidar packets of the third frame, IMU packets): whole records,
  // so the file is sound but the frame lacks columns.
  frames.resize(frames.size() - 20);
  const ReadResult result = read_pcap(write_scratch("incomplete", test::write_pcap(frames)), json);
  ASSERT_EQ(result.scans.size(), 3u);
  EXPECT_LT(result.scans[2].valid_count(), result.scans[1].valid_count());
  ASSERT_EQ(result.stats.warning_count, 1u);
  EXPECT_NE(result.stats.warnings[0].find("frame 2 is incomplete"), std::string::npos);
}

TEST(OusterPcapInput, PacketsCutBySnapLengthAreSkippedAndCounted) {
  FEATSENSE_SHARED_FILE(pcap, kOs1Pcap);
  FEATSENSE_SHARED_FILE(json, kOs1Json);
  std::vector<CapturedFrame> frames = test::read_pcap_frames(test::read_file(pcap));
  // A capture with a 1000-byte snap length from the 100th record on: those lidar packets are
  // cut, the IP length says more than the record holds.
  size_t cut = 0;
  for (size_t k = 100; k < frames.size(); ++k) {
    if (frames[k].bytes.size() > 1000) {
      frames[k].bytes.resize(1000);
      ++cut;
    }
  }
  const ReadResult result = read_pcap(write_scratch("snap", test::write_pcap(frames)), json);
  ASSERT_EQ(result.scans.size(), 2u);  // the second frame ends cut short
  bool counted = false;
  for (const std::string& warning : result.stats.warnings) {
    counted |= warning.find(std::to_string(cut) + " IP/UDP packets were damaged or cut short") !=
               std::string::npos;
  }
  EXPECT_TRUE(counted);
}

TEST(OusterPcapInput, GarbageBytes) {
  FEATSENSE_SHARED_FILE(pcap, kOs1Pcap);
  FEATSENSE_SHARED_FILE(json, kOs1Json);
  std::string noise(20000, '\0');
  uint32_t state = 12345;
  for (char& c : noise) {
    state = state * 1664525u + 1013904223u;  // a fixed pseudo-random sequence
    c = static_cast<char>(state >> 24);
  }
  EXPECT_NE(error_reading(write_scratch("garbage", noise), json).find("not a pcap file"),
            std::string::npos);
  // A sound header followed by noise: no lidar packet, an error naming the expected size.
  const std::string header = test::write_pcap({});
  EXPECT_NE(error_reading(write_scratch("garbage", header + noise), json).find("no lidar packets"),
            std::string::npos);
  // Noise after the real records: all frames, then a warning.
  const std::string bytes = test::read_file(pcap);
  const ReadResult result = read_pcap(write_scratch("garbage", bytes + noise), json);
  EXPECT_EQ(result.scans.size(), 3u);
  EXPECT_GE(result.stats.warning_count, 1u);
}

TEST(OusterPcapInput, NoLidarPacketsOfTheRightSize) {
  FEATSENSE_SHARED_FILE(pcap, kOs1Pcap);
  FEATSENSE_SHARED_FILE(json, kOs1Json);
  std::vector<CapturedFrame> imu_only;
  for (const CapturedFrame& f : test::read_pcap_frames(test::read_file(pcap))) {
    if (f.bytes.size() != kLidarFrameBytes) imu_only.push_back(f);
  }
  ASSERT_EQ(imu_only.size(), 30u);  // data/README.md: 222 records, 192 of them lidar
  const std::string message = error_reading(write_scratch("imu", test::write_pcap(imu_only)), json);
  EXPECT_NE(message.find("no lidar packets of 8448 bytes"), std::string::npos) << message;
  EXPECT_NE(message.find("30 IMU packets (port 7503)"), std::string::npos) << message;

  // Metadata of another profile: the packets do not fit it, and the message says which sizes
  // were there.
  std::string text = test::read_file(json);
  text.replace(text.find("RNG15_RFL8_NIR8"), 15, "LEGACY");
  const fs::path legacy_json = test::scratch_dir("legacy-meta") / "legacy.json";
  test::write_file(legacy_json, text);
  const std::string mismatch = error_reading(pcap, legacy_json);
  EXPECT_NE(mismatch.find("192 of 8448 bytes (port 7502)"), std::string::npos) << mismatch;
}

/// The real capture with each datagram larger than 1500 bytes split into IP fragments of
/// 1500 bytes; optionally each datagram's fragments reversed, and the fragments of pairs of
/// consecutive datagrams interleaved (A0 B0 A1 B1 ...).
std::string fragmented_capture(const std::vector<CapturedFrame>& frames, bool reverse,
                               bool interleave) {
  std::vector<std::vector<CapturedFrame>> datagrams;
  for (const CapturedFrame& frame : frames) {
    std::vector<CapturedFrame> pieces;
    for (auto& fragment : test::fragment_ipv4(frame.bytes, 1500)) {
      pieces.push_back({frame.seconds, frame.fraction, std::move(fragment)});
    }
    if (reverse) std::reverse(pieces.begin(), pieces.end());
    datagrams.push_back(std::move(pieces));
  }
  std::vector<CapturedFrame> out;
  const size_t step = interleave ? 2 : 1;
  for (size_t d = 0; d < datagrams.size(); d += step) {
    const size_t last = std::min(d + step, datagrams.size());
    for (size_t i = 0;; ++i) {
      bool any = false;
      for (size_t k = d; k < last; ++k) {
        if (i < datagrams[k].size()) {
          out.push_back(datagrams[k][i]);
          any = true;
        }
      }
      if (!any) break;
    }
  }
  return test::write_pcap(out);
}

TEST(OusterPcapInput, FragmentedPacketsGiveIdenticalScans) {
  FEATSENSE_SHARED_FILE(pcap, kOs1Pcap);
  FEATSENSE_SHARED_FILE(json, kOs1Json);
  const ReadResult original = read_pcap(pcap, json);
  ASSERT_EQ(original.scans.size(), 3u);
  const std::vector<CapturedFrame> frames = test::read_pcap_frames(test::read_file(pcap));
  for (const auto& [reverse, interleave] :
       {std::make_pair(false, false), std::make_pair(true, false), std::make_pair(true, true)}) {
    SCOPED_TRACE(std::string(reverse ? "reversed" : "in order") +
                 (interleave ? ", interleaved" : ""));
    const std::string bytes = fragmented_capture(frames, reverse, interleave);
    EXPECT_GT(bytes.size(), test::read_file(pcap).size() + 192 * 5 * 34);  // 6 fragments each
    const ReadResult result = read_pcap(write_scratch("fragments", bytes), json);
    expect_identical(result.scans, original.scans);
    EXPECT_EQ(result.stats.warning_count, 0u);
  }
}

TEST(OusterPcapInput, OtherPortsAndPcapVariantsGiveIdenticalScans) {
  FEATSENSE_SHARED_FILE(pcap, kOs1Pcap);
  FEATSENSE_SHARED_FILE(json, kOs1Json);
  const ReadResult original = read_pcap(pcap, json);
  std::vector<CapturedFrame> frames = test::read_pcap_frames(test::read_file(pcap));
  // Lidar packets are matched by size, so a sensor configured for port 9999 works too.
  for (CapturedFrame& f : frames) {
    if (f.bytes.size() == kLidarFrameBytes) test::set_be16(f.bytes, 36, 9999);
  }
  expect_identical(read_pcap(write_scratch("port", test::write_pcap(frames)), json).scans,
                   original.scans);
  // Big-endian with nanosecond stamps, and Linux cooked framing.
  test::PcapWriteOptions options;
  options.big_endian = true;
  options.nanoseconds = true;
  expect_identical(
      read_pcap(write_scratch("variant", test::write_pcap(frames, options)), json).scans,
      original.scans);
  std::vector<CapturedFrame> cooked = frames;
  for (CapturedFrame& f : cooked) {
    std::vector<uint8_t> bytes(16, 0);
    bytes[14] = 0x08;
    bytes.insert(bytes.end(), f.bytes.begin() + 14, f.bytes.end());
    f.bytes = std::move(bytes);
  }
  options = {};
  options.link_type = 113;
  expect_identical(
      read_pcap(write_scratch("cooked", test::write_pcap(cooked, options)), json).scans,
      original.scans);
}

TEST(OusterPcapInput, FindsTheMetadataWithTheLongestCommonPrefix) {
  FEATSENSE_SHARED_FILE(pcap, kOs1Pcap);
  FEATSENSE_SHARED_FILE(json, kOs1Json);
  // The shared folder itself holds the OS0's JSON as well; the OS1's shares the longer prefix.
  std::unique_ptr<ScanSource> source = open_ouster_pcap(pcap.string(), {});
  EXPECT_EQ(source->info().sensor.name, "os-1-128");

  const fs::path dir = test::scratch_dir("discovery");
  const fs::path copy = dir / "drive_2024_morning.pcap";
  fs::copy_file(pcap, copy);
  std::string message;
  try {
    open_ouster_pcap(copy.string(), {});
  } catch (const InputError& e) {
    message = e.what();
  }
  EXPECT_NE(message.find("no Ouster metadata found"), std::string::npos) << message;
  EXPECT_NE(message.find(dir.string()), std::string::npos) << message;

  fs::copy_file(json, dir / "drive_2024.json");
  test::write_file(dir / "drive_2023.json", "{}");  // shorter common prefix: not chosen
  test::write_file(dir / "notes.txt", "");
  EXPECT_EQ(open_ouster_pcap(copy.string(), {})->info().detail, "OS-1-128 1024x10 RNG15_RFL8_NIR8");

  test::write_file(dir / "drive_2024_evening.json", "{}");  // now this one shares more
  try {
    open_ouster_pcap(copy.string(), {});
    ADD_FAILURE() << "the broken drive_2024_evening.json should have been chosen";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("drive_2024_evening.json"), std::string::npos);
  }
  // --meta wins over the search.
  SourceOptions options;
  options.meta_path = (dir / "drive_2024.json").string();
  EXPECT_NO_THROW(open_ouster_pcap(copy.string(), options));
  options.meta_path = (dir / "absent.json").string();
  try {
    open_ouster_pcap(copy.string(), options);
    ADD_FAILURE() << "a missing --meta file must be an error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("absent.json"), std::string::npos);
  }
}

}  // namespace
}  // namespace featsense::slam
