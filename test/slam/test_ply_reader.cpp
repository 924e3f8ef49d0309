// The PLY point-cloud reader: ascii and binary files of either byte order written by a small
// independent writer, elements before and after the vertices, and headers that lie.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>

#include "common/test_data.hpp"
#include "featsense/slam/io/cloud_files.hpp"
#include "featsense/slam/io/readers.hpp"

namespace featsense::slam {
namespace {

namespace fs = std::filesystem;

/// A property as the test writer stores it; `type` is a PLY type name.
struct TestProperty {
  std::string type;
  std::string name;
};

enum class Format { kAscii, kLittle, kBig };

void put(std::string& out, const std::string& type, double v, bool big) {
  uint8_t b[8];
  size_t n = 0;
  if (type == "float") {
    const float x = static_cast<float>(v);
    std::memcpy(b, &x, n = 4);
  } else if (type == "double") {
    std::memcpy(b, &v, n = 8);
  } else if (type == "uchar" || type == "char") {
    b[0] = static_cast<uint8_t>(static_cast<int>(v));
    n = 1;
  } else if (type == "ushort" || type == "short") {
    const int16_t x = static_cast<int16_t>(static_cast<int>(v));
    std::memcpy(b, &x, n = 2);
  } else if (type == "int" || type == "uint") {
    const int32_t x = static_cast<int32_t>(static_cast<int64_t>(v));
    std::memcpy(b, &x, n = 4);
  }
  if (big) std::reverse(b, b + n);  // the test host is little-endian
  out.append(reinterpret_cast<const char*>(b), n);
}

/// Vertices with `properties`; `faces` triangles before (faces_first) or after them.
std::string test_ply(const std::vector<TestProperty>& properties,
                     const std::vector<std::vector<double>>& vertices, Format format, int faces = 0,
                     bool faces_first = false) {
  std::ostringstream h;
  h << "ply\nformat "
    << (format == Format::kAscii    ? "ascii"
        : format == Format::kLittle ? "binary_little_endian"
                                    : "binary_big_endian")
    << " 1.0\ncomment written by the test\n";
  const std::string face_header =
      "element face " + std::to_string(faces) + "\nproperty list uchar int vertex_indices\n";
  if (faces_first) h << face_header;
  h << "element vertex " << vertices.size() << "\n";
  for (const auto& p : properties) h << "property " << p.type << " " << p.name << "\n";
  if (!faces_first && faces > 0) h << face_header;
  h << "end_header\n";
  std::string out = h.str();
  const bool big = format == Format::kBig;
  std::string face_data, vertex_data;
  for (int f = 0; f < faces; ++f) {
    if (format == Format::kAscii) {
      face_data += "3 " + std::to_string(f) + " " + std::to_string(f + 1) + " 0\n";
    } else {
      put(face_data, "uchar", 3, big);
      for (int k : {f, f + 1, 0}) put(face_data, "int", k, big);
    }
  }
  for (const auto& v : vertices) {
    if (format == Format::kAscii) {
      std::ostringstream line;
      line.precision(17);
      for (size_t k = 0; k < v.size(); ++k) line << (k ? " " : "") << v[k];
      vertex_data += line.str() + "\n";
    } else {
      for (size_t k = 0; k < v.size(); ++k) put(vertex_data, properties[k].type, v[k], big);
    }
  }
  return out + (faces_first ? face_data + vertex_data : vertex_data + face_data);
}

const std::vector<TestProperty> kProperties = {
    {"double", "x"},   {"double", "y"}, {"double", "z"}, {"ushort", "intensity"},
    {"uchar", "ring"}, {"float", "t"},  {"float", "nx"}, {"uchar", "red"}};

std::vector<std::vector<double>> vertices(int n) {
  std::mt19937 random(9);
  std::uniform_real_distribution<double> coordinate(-50, 50);
  std::vector<std::vector<double>> out;
  for (int i = 0; i < n; ++i) {
    out.push_back({coordinate(random), coordinate(random), coordinate(random),
                   static_cast<double>(i * 13 % 4000), static_cast<double>(i % 32), i * 1e-4, 0.5,
                   200});
  }
  return out;
}

std::string decode_error(const std::string& bytes) {
  try {
    decode_ply(bytes, "test.ply");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(PlyReader, ReadsEveryFormatExactly) {
  const auto v = vertices(300);
  for (Format format : {Format::kAscii, Format::kLittle, Format::kBig}) {
    for (int faces : {0, 5}) {
      for (bool faces_first : {false, true}) {
        SCOPED_TRACE(std::to_string(static_cast<int>(format)) + " faces " + std::to_string(faces) +
                     (faces_first ? " first" : " after"));
        const DecodedCloud d =
            decode_ply(test_ply(kProperties, v, format, faces, faces_first), "cloud.ply");
        EXPECT_EQ(d.format, "ply");
        EXPECT_FALSE(d.organized());
        EXPECT_EQ(d.fields,
                  (std::vector<std::string>{"x", "y", "z", "intensity", "ring", "t", "nx", "red"}));
        ASSERT_EQ(d.cloud.size(), v.size());
        ASSERT_EQ(d.cloud.channels.size(), 1u);
        for (size_t i = 0; i < v.size(); ++i) {
          // Doubles become the floats of Scan: the nearest float.
          EXPECT_EQ(d.cloud.xyz[i], Eigen::Vector3d(v[i][0], v[i][1], v[i][2]).cast<float>());
          EXPECT_EQ(d.cloud.channels[0].values[i], static_cast<float>(v[i][3]));
          EXPECT_EQ(d.cloud.ring[i], static_cast<int>(v[i][4]));
          // A float `t` counts seconds.
          EXPECT_EQ(d.cloud.time_offset_s[i], static_cast<float>(v[i][5]));
        }
      }
    }
  }
}

TEST(PlyReader, IntegerCoordinatesAreAccepted) {
  const DecodedCloud d = decode_ply(
      test_ply({{"int", "x"}, {"short", "y"}, {"uchar", "z"}}, {{-7, 300, 9}}, Format::kBig),
      "int.ply");
  EXPECT_EQ(d.cloud.xyz[0], Eigen::Vector3f(-7, 300, 9));
}

TEST(PlyReader, GarbageTimesBecomeZero) {
  // Found by fuzzing: a double time of 1e300 gave an infinite float offset.
  const DecodedCloud d =
      decode_ply(test_ply({{"float", "x"}, {"float", "y"}, {"float", "z"}, {"double", "time"}},
                          {{1, 2, 3, 1e300}, {1, 2, 4, 0}, {1, 2, 5, -1e300}}, Format::kBig),
                 "garbage.ply");
  for (float t : d.cloud.time_offset_s) EXPECT_EQ(t, 0.0f);
}

TEST(PlyReader, UnorganizedCloudGoesThroughOrganize) {
  // Points on the beams of an HDL-32 with their ring (Velodyne: ring 0 lowest).
  const config::SensorModel hdl32 = config::sensor_preset("hdl32");
  std::vector<std::vector<double>> v;
  for (int ring = 0; ring < 32; ++ring) {
    const double e = hdl32.elevation_rad[static_cast<size_t>(31 - ring)];
    for (int c = 0; c < 2170; c += 31) {
      const double a = -2 * M_PI * c / 2170, r = 5 + ring;
      v.push_back({r * std::cos(e) * std::cos(a), r * std::cos(e) * std::sin(a), r * std::sin(e),
                   static_cast<double>(c), static_cast<double>(ring), 0, 0, 0});
    }
  }
  const fs::path file = test::scratch_dir("ply_reader_organize") / "hdl32.ply";
  const std::string bytes = test_ply(kProperties, v, Format::kLittle);
  std::ofstream(file, std::ios::binary)
      .write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  const auto source = open_ply_file(file.string(), {});
  EXPECT_EQ(source->info().format, "ply");
  EXPECT_EQ(source->info().sensor.name, "hdl32");
  const std::optional<Scan> scan = source->next();
  ASSERT_TRUE(scan);
  EXPECT_EQ(scan->valid_count(), v.size());
  for (int row = 0; row < 32; ++row) {
    for (int c = 0; c < 2170; c += 31) {
      const size_t i = scan->index(row, c);
      ASSERT_TRUE(scan->valid[i]) << row << " " << c;
      EXPECT_EQ(scan->channel("intensity")->values[i], c);
      EXPECT_NEAR(scan->range_m[i], 5 + (31 - row), 1e-5);
    }
  }
}

TEST(PlyReader, HeaderLiesAreErrorsNamingTheProblem) {
  const auto v = vertices(20);
  const std::string binary = test_ply(kProperties, v, Format::kLittle, 3, true);
  const std::string ascii = test_ply(kProperties, v, Format::kAscii, 3, true);
  auto replace = [](std::string text, const std::string& from, const std::string& to) {
    const size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return text.replace(at, from.size(), to);
  };
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"", "not a PLY file"},
      {"ply\n", "truncated PLY header"},
      {replace(binary, "element vertex 20", "element vertex 21"),
       "21 vertex records of 36 bytes promised, but 720 bytes remain"},
      {replace(binary, "element vertex 20", "element vertex 99999999999"),
       "promises more vertices than"},
      {replace(binary, "element face 3", "element face 4"), "data ends inside"},
      {replace(binary, "element face 3", "element face 4000000000"), "data ends inside face"},
      {replace(binary, "element vertex 20", "element vertex -1"), "is not a non-negative integer"},
      {replace(binary, "property double x", "property quad x"), "unknown type 'quad'"},
      {replace(binary, "property double x", "property list uchar double x"), "no field 'x'"},
      {replace(binary, "property list uchar int", "property list float int"),
       "list count must have an integer type"},
      {replace(binary, "format binary_little_endian 1.0", "format binary_middle_endian 1.0"),
       "unknown format"},
      {replace(binary, "format binary_little_endian 1.0", "format binary_little_endian 2.0"),
       "expected 'format"},
      {replace(binary, "format binary_little_endian 1.0\n", ""), "end_header before any format"},
      {replace(binary, "element vertex", "element points"), "without a 'vertex' element"},
      {replace(binary, "comment", "remark"), "'remark' is not a PLY header keyword"},
      {replace(binary, "property double y\n", "property double y\nproperty double x\n"),
       "field 'x' appears twice"},
      {replace(ascii, "element vertex 20", "element vertex 25"),
       "the data ends; the header promises 25"},
      {replace(ascii, "\n3 0 1 0", "\n7 0 1 0"), "list 'vertex_indices' claims 7 items"},
      {replace(ascii, "end_header\n", "end_header\n1 2 3\n"),
       "face 0: too many values on its line"},
      {replace(ascii, "end_header\n3 0 1 0\n", "end_header\n3 0 1\n"),
       "face 0: list 'vertex_indices' claims 3 items"},
      {replace(ascii, "end_header\n", "end_header\nfoo "), "'foo' is not a number"},
      {replace(ascii, "property double z\n", "property double z\nproperty double w\n"),
       "vertex 0: too few values on its line"},
  };
  for (const auto& [bytes, expected] : cases) {
    const std::string message = decode_error(bytes);
    EXPECT_NE(message.find(expected), std::string::npos)
        << "expected '" << expected << "', got '" << message << "'";
    EXPECT_EQ(message.rfind("test.ply", 0), 0u) << message;
  }
  // A face list whose count runs past the end (binary).
  std::string long_list = test_ply(kProperties, v, Format::kLittle, 1, true);
  long_list[long_list.find("end_header\n") + 11] = static_cast<char>(250);
  EXPECT_NE(decode_error(long_list).find("data ends inside"), std::string::npos)
      << decode_error(long_list);
}

TEST(PlyReader, TruncatedFilesNeverCrash) {
  const auto v = vertices(40);
  for (Format format : {Format::kLittle, Format::kBig, Format::kAscii}) {
    const std::string full = test_ply(kProperties, v, format, 4, true);
    const size_t header_end = full.find("end_header\n") + 11;
    for (size_t length = 0; length < full.size(); length += (length < 300 ? 1 : 5)) {
      const std::string message = decode_error(full.substr(0, length));
      if (format != Format::kAscii && length < full.size()) {
        EXPECT_FALSE(message.empty())
            << "length " << length << " of " << full.size() << " (header " << header_end << ")";
      }
    }
  }
}

TEST(PlyReader, EmptyFileIsAnError) {
  const fs::path dir = test::scratch_dir("ply_reader_empty");
  std::ofstream(dir / "empty.ply").close();
  try {
    open_ply_file((dir / "empty.ply").string(), {});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("empty.ply: empty file"), std::string::npos);
  }
}

}  // namespace
}  // namespace featsense::slam
