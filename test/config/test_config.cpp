#include <gtest/gtest.h>

#include <map>
#include <set>

#include "featsense/config/config.hpp"
#include "featsense/config/config_error.hpp"

namespace featsense::config {
namespace {

const std::string kDefaultYaml = std::string(FEATSENSE_SOURCE_DIR) + "/config/default.yaml";

/// The message of the ConfigError that `f` throws ("" when it throws none).
template <typename F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(Config, DefaultYamlStatesEveryKeyWithItsBuiltInDefault) {
  const Config from_file = load_config(kDefaultYaml);
  const Config defaults;
  std::set<std::string> stated;
  for (const auto& [key, where] : from_file.explicit_keys) stated.insert(key);
  for (const std::string& key : config_keys()) {
    EXPECT_EQ(stated.count(key), 1u) << key << " is not stated in default.yaml";
    EXPECT_EQ(value_text(from_file, key), value_text(defaults, key)) << key;
  }
  EXPECT_EQ(stated.size(), config_keys().size());
  EXPECT_EQ(to_yaml(from_file), to_yaml(defaults));  // every digit, not only the shown ones
}

TEST(Config, DefaultsAreThoseOfTheDesign) {
  const Config c;
  EXPECT_DOUBLE_EQ(c.map.voxel_size_m, 0.064);
  EXPECT_EQ(c.map.size_m, (std::array<double, 3>{40, 40, 15}));
  EXPECT_EQ(c.map.backend, Backend::kAuto);
  EXPECT_EQ(c.sensor.preset, "auto");
  EXPECT_FALSE(c.sensor.min_range_m.has_value());
}

TEST(Config, ToYamlRoundTrips) {
  const Config changed = load_config_text(
      "map: {voxel_size: 0.05, size: [20, 30, 10], backend: cpu}\n"
      "sensor: {preset: vlp16, max_range: 80}\nodometry: {deskew: false}\n",
      "test");
  const Config again = load_config_text(to_yaml(changed), "round trip");
  EXPECT_EQ(to_yaml(again), to_yaml(changed));
  EXPECT_DOUBLE_EQ(again.map.voxel_size_m, 0.05);
  EXPECT_EQ(again.map.backend, Backend::kCpu);
  EXPECT_EQ(again.sensor.preset, "vlp16");
  EXPECT_DOUBLE_EQ(again.sensor.max_range_m.value(), 80.0);
  EXPECT_FALSE(again.odometry.deskew);
}

TEST(Config, OverridesApplyInOrderAfterTheFile) {
  const Config c = load_config_text("map: {voxel_size: 0.1}\n", "file",
                                    {"map.voxel_size=0.08", "map.size=[10,12,5]",
                                     "odometry.optimization_steps=5", "map.voxel_size=0.07"});
  EXPECT_DOUBLE_EQ(c.map.voxel_size_m, 0.07);
  EXPECT_EQ(c.map.size_m, (std::array<double, 3>{10, 12, 5}));
  EXPECT_EQ(c.odometry.optimization_steps, 5);
}

TEST(Config, UnknownKeyNamesItAndSuggestsTheClosest) {
  const std::string file_error =
      error_of([] { load_config_text("map:\n  voxelsize: 0.1\n", "my.yaml"); });
  EXPECT_NE(file_error.find("my.yaml:2"), std::string::npos) << file_error;
  EXPECT_NE(file_error.find("map.voxelsize"), std::string::npos) << file_error;
  EXPECT_NE(file_error.find("did you mean 'map.voxel_size'"), std::string::npos) << file_error;

  const std::string set_error = error_of([] { load_config({}, {"map.trunaction=0.3"}); });
  EXPECT_NE(set_error.find("did you mean 'map.truncation'"), std::string::npos) << set_error;

  const std::string section_error = error_of([] { load_config_text("mapp: {}\n", "f"); });
  EXPECT_NE(section_error.find("did you mean 'map'"), std::string::npos) << section_error;
}

TEST(Config, WrongTypesAreErrorsNamingTheKey) {
  for (const auto& [assignment, key] : std::vector<std::pair<std::string, std::string>>{
           {"map.voxel_size=fast", "map.voxel_size"},
           {"map.size=[1,2]", "map.size"},
           {"map.size=12", "map.size"},
           {"odometry.deskew=maybe", "odometry.deskew"},
           {"odometry.optimization_steps=2.5", "odometry.optimization_steps"},
           {"map.backend=gpu", "map.backend"},
           {"sensor.preset=os1-129", "sensor.preset"},
           {"map.voxel_size=.nan", "map.voxel_size"},
           {"sensor.imu=sometimes", "sensor.imu"},
           {"sensor.imu_topic=[a,b]", "sensor.imu_topic"},
           {"sensor.imu_rotation=[0,0]", "sensor.imu_rotation"},
           {"sensor.imu_rotation=[0,.inf,0]", "finite"},
           {"sensor.self_box=[0,0,0,1,1]", "sensor.self_box"},
           {"sensor.self_box=[0,0,0,1,-1,1]", "y minimum must be below"},
           {"sensor.self_box=box", "sensor.self_box"},
       }) {
    const std::string message = error_of([&] { load_config({}, {assignment}); });
    EXPECT_NE(message.find(key), std::string::npos) << assignment << " -> '" << message << "'";
  }
  EXPECT_NE(
      error_of([] { load_config({}, {"sensor.preset=os1-12"}); }).find("did you mean 'os1-128'"),
      std::string::npos);
}

TEST(Config, AbsurdValuesAreRejected) {
  for (const char* assignment :
       {"map.voxel_size=0", "map.voxel_size=-1", "map.voxel_size=100", "map.truncation=0",
        "map.max_weight=0", "map.size=[40,40,-1]", "map.shift_threshold=0",
        "odometry.optimization_steps=0", "sensor.min_range=-1", "sensor.max_range=0",
        "refine.distance=-2", "sensor.imu_rotation=[0,0,361]", "sensor.imu_rotation=[-400,0,0]"}) {
    EXPECT_FALSE(error_of([&] { load_config({}, {assignment}); }).empty()) << assignment;
  }
}

TEST(Config, RelationsBetweenKeysAreChecked) {
  EXPECT_NE(error_of([] { load_config({}, {"map.truncation=0.01"}); }).find("at least one voxel"),
            std::string::npos);
  EXPECT_NE(error_of([] {
              load_config({}, {"sensor.min_range=5", "sensor.max_range=2"});
            }).find("sensor.min_range"),
            std::string::npos);
  EXPECT_NE(error_of([] {
              load_config({}, {"map.voxel_size=0.005", "map.size=[2000,2000,100]"});
            }).find("voxels"),
            std::string::npos);
  EXPECT_NE(error_of([] { load_config({}, {"map.shift_threshold=30"}); }).find("shift_threshold"),
            std::string::npos);
}

TEST(Config, KnowsWhichKeysWereSetAndWhere) {
  EXPECT_TRUE(load_config({}).explicit_keys.empty());
  EXPECT_TRUE(load_config_text("", "empty.yaml").explicit_keys.empty());
  EXPECT_TRUE(load_config_text("map:\n", "no_keys.yaml").explicit_keys.empty());

  const Config c = load_config_text("sensor:\n  preset: vlp16\nmap:\n  voxel_size: 0.1\n",
                                    "my.yaml", {"map.truncation=0.3", "map.voxel_size=0.08"},
                                    {{"map.backend", "cpu", "--backend cpu"}});
  EXPECT_EQ(c.explicit_keys,
            (std::map<std::string, std::string>{{"sensor.preset", "my.yaml:2"},
                                                {"map.voxel_size", "--set map.voxel_size=0.08"},
                                                {"map.truncation", "--set map.truncation=0.3"},
                                                {"map.backend", "--backend cpu"}}));
  EXPECT_TRUE(c.is_explicit("map.voxel_size"));
  EXPECT_FALSE(c.is_explicit("map.size"));
  EXPECT_FALSE(c.is_explicit("odometry.deskew"));
}

TEST(Config, AKeySetToItsDefaultIsStillSet) {
  const Config set = load_config({}, {"map.voxel_size=0.064"});
  EXPECT_DOUBLE_EQ(set.map.voxel_size_m, Config{}.map.voxel_size_m);
  EXPECT_TRUE(set.is_explicit("map.voxel_size"));
  EXPECT_FALSE(set.is_explicit("map.truncation"));

  const Config in_file = load_config_text("map: {truncation: 0.25}\n", "f.yaml");
  EXPECT_TRUE(in_file.is_explicit("map.truncation"));
  EXPECT_EQ(in_file.explicit_keys.at("map.truncation"), "f.yaml:1");

  const Config by_option = load_config({}, {}, {{"map.backend", "auto", "--backend auto"}});
  EXPECT_TRUE(by_option.is_explicit("map.backend"));
  // A null optional key ("the sensor's own") given explicitly is set too.
  EXPECT_TRUE(load_config({}, {"sensor.max_range=null"}).is_explicit("sensor.max_range"));
}

TEST(Config, OptionsGoThroughTheSchemaAfterTheSetOnes) {
  const Config c = load_config(
      {}, {"map.backend=cuda", "map.voxel_size=0.1"},
      {{"map.backend", "cpu", "--backend cpu"}, {"map.size", "[20,30,10]", "--map 20x30x10"}});
  EXPECT_EQ(c.map.backend, Backend::kCpu);
  EXPECT_DOUBLE_EQ(c.map.voxel_size_m, 0.1);
  EXPECT_EQ(c.map.size_m, (std::array<double, 3>{20, 30, 10}));
  EXPECT_EQ(c.explicit_keys.at("map.backend"), "--backend cpu");

  // The one parser's messages, naming the option and the key.
  const std::string backend = error_of([] {
    load_config({}, {}, {{"map.backend", "gpu", "--backend gpu"}});
  });
  EXPECT_EQ(backend.rfind("--backend gpu: map.backend: unknown value 'gpu'", 0), 0u) << backend;
  EXPECT_NE(backend.find("choose one of: auto cuda cpu"), std::string::npos) << backend;
  const std::string voxel = error_of([] {
    load_config({}, {}, {{"map.voxel_size", "fast", "--voxel fast"}});
  });
  EXPECT_EQ(voxel, "--voxel fast: map.voxel_size: expected a number");
  const std::string range = error_of([] {
    load_config({}, {}, {{"map.voxel_size", "5", "--voxel 5"}});
  });
  EXPECT_NE(range.find("--voxel 5: map.voxel_size: value 5 is out of range"), std::string::npos)
      << range;
  const std::string size = error_of([] {
    load_config({}, {}, {{"map.size", "[40,40]", "--map 40x40"}});
  });
  EXPECT_EQ(size, "--map 40x40: map.size: expected a list of 3 numbers");
  // Relations between keys hold for options too.
  EXPECT_NE(error_of([] {
              load_config({}, {}, {{"map.truncation", "0.01", "--truncation 0.01"}});
            }).find("at least one voxel"),
            std::string::npos);
}

TEST(Config, ValueTextIsShort) {
  const Config c;
  EXPECT_EQ(value_text(c, "map.voxel_size"), "0.064");
  EXPECT_EQ(value_text(c, "map.size"), "[40, 40, 15]");
  EXPECT_EQ(value_text(c, "map.backend"), "auto");
  EXPECT_EQ(value_text(c, "sensor.min_range"), "null");
  EXPECT_EQ(value_text(c, "odometry.deskew"), "true");
  EXPECT_EQ(value_text(c, "odometry.optimization_steps"), "3");
  EXPECT_EQ(value_text(c, "odometry.surface_voxel"), "0.2");
  EXPECT_NE(error_of([] { value_text(Config{}, "map.voxelsize"); }).find("map.voxel_size"),
            std::string::npos);
}

TEST(Config, TheSelfBoxIsNullOrSixNumbers) {
  EXPECT_EQ(value_text(Config{}, "sensor.self_box"), "null");
  const Config c = load_config({}, {"sensor.self_box=[-1, -0.8, -1.5, 2.5, 0.8, 0.2]"});
  ASSERT_TRUE(c.sensor.self_box.has_value());
  EXPECT_EQ((*c.sensor.self_box)[3], 2.5);
  EXPECT_EQ(value_text(c, "sensor.self_box"), "[-1, -0.8, -1.5, 2.5, 0.8, 0.2]");
  EXPECT_FALSE(load_config({}, {"sensor.self_box=[0,0,0,1,1,1]", "sensor.self_box=null"})
                   .sensor.self_box.has_value());
}

TEST(Config, NullRangeMeansTheSensorsOwn) {
  const Config c = load_config({}, {"sensor.max_range=50", "sensor.max_range=null"});
  EXPECT_FALSE(c.sensor.max_range_m.has_value());
}

TEST(Config, BadFilesGiveClearErrors) {
  EXPECT_NE(
      error_of([] { load_config(std::string("/nonexistent/featsense.yaml")); }).find("cannot open"),
      std::string::npos);
  EXPECT_NE(error_of([] { load_config_text("map: [1, 2\n", "broken.yaml"); }).find("broken.yaml"),
            std::string::npos);
  EXPECT_NE(error_of([] { load_config_text("- 1\n- 2\n", "list.yaml"); }).find("mapping"),
            std::string::npos);
  EXPECT_NE(error_of([] { load_config_text("map: 3\n", "scalar.yaml"); }).find("map"),
            std::string::npos);
  EXPECT_NE(error_of([] { load_config({}, {"voxel_size"}); }).find("key=value"), std::string::npos);
  // An empty file is a valid config: all defaults.
  EXPECT_EQ(to_yaml(load_config_text("", "empty.yaml")), to_yaml(Config{}));
}

}  // namespace
}  // namespace featsense::config
