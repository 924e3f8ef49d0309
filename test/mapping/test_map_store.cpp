// A continued map keeps its geometry: the configuration takes the old map's voxel size and
// tau where they were not set, refuses an explicit other value, and a store is never opened
// on a configuration that did not take them.

#include <gtest/gtest.h>

#include "common/test_data.hpp"
#include "featsense/config/config_error.hpp"
#include "featsense/mapping/map_store.hpp"
#include "featsense/storage/hdf5_chunk_store.hpp"

namespace featsense::mapping {
namespace {

storage::MapMetadata old_geometry() {
  storage::MapMetadata old_map;
  old_map.voxel_size_m = 0.1;
  old_map.truncation_m = 0.3;
  return old_map;
}

TEST(MapStore, AContinuedMapsGeometryWinsOverDefaults) {
  std::vector<std::string> said;
  RunEvents events;
  events.log = [&](LogLevel, const std::string& text) { said.push_back(text); };
  const config::Config config =
      with_map_geometry(config::Config{}, old_geometry(), "old.h5", events);
  EXPECT_EQ(config.map.voxel_size_m, 0.1);
  EXPECT_EQ(config.map.truncation_m, 0.3);
  ASSERT_EQ(said.size(), 2u) << "each value taken from the map is said";
  EXPECT_NE(said[0].find("map.voxel_size = 0.1 of the continued map old.h5"), std::string::npos);
}

TEST(MapStore, AnExplicitOtherGeometryIsAnErrorNamingBoth) {
  config::Config config;
  config.explicit_keys["map.voxel_size"] = "--voxel 0.064";
  try {
    with_map_geometry(config, old_geometry(), "old.h5");
    FAIL() << "no error";
  } catch (const config::ConfigError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("0.064"), std::string::npos) << what;
    EXPECT_NE(what.find("--voxel 0.064"), std::string::npos) << what;
    EXPECT_NE(what.find("0.1 (old.h5)"), std::string::npos) << what;
  }
  config.map.voxel_size_m = 0.1;  // explicit and the same: fine
  EXPECT_EQ(with_map_geometry(config, old_geometry(), "old.h5").map.truncation_m, 0.3);
}

TEST(MapStore, TheStoreOfAContinuedMapOpensOnlyWithItsGeometry) {
  const std::filesystem::path dir = test::scratch_dir("map_store_geometry");
  const std::filesystem::path old_path = dir / "old.h5";
  {
    storage::MapMetadata metadata = old_geometry();
    metadata.max_weight = 10.0;
    storage::Hdf5ChunkStore old_map(old_path, storage::OpenMode::kCreate, metadata);
    old_map.close();
  }
  const config::Config defaults;
  EXPECT_THROW(open_map_store(dir / "new.h5", defaults, "os1-128", old_path.string(), false),
               std::logic_error);
  const config::Config continued = with_continued_geometry(defaults, old_path.string());
  EXPECT_EQ(continued.map.voxel_size_m, 0.1);
  MapStore store = open_map_store(dir / "new.h5", continued, "os1-128", old_path.string(), false);
  EXPECT_EQ(store.store->metadata().voxel_size_m, 0.1);
  // No such file: nothing to take; opening the store says so.
  EXPECT_EQ(with_continued_geometry(defaults, (dir / "none.h5").string()).map.voxel_size_m,
            defaults.map.voxel_size_m);
}

}  // namespace
}  // namespace featsense::mapping
