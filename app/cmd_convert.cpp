// featsense convert: pulls the frames out of a recording as one file per frame.

#include <spdlog/spdlog.h>

#include <cinttypes>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "commands.hpp"
#include "featsense/slam/io/scan_writers.hpp"
#include "progress.hpp"
#include "source_options.hpp"

namespace featsense::app {
namespace {

struct ConvertOptions {
  InputOptions input;
  std::string output_dir;
  std::string format = "pcd";
};

/// frame_<index>_<stamp ns>.<ext>: name order is frame order, and the folder reader takes
/// the trailing number as the frame's time stamp, so a converted folder maps like the input.
std::string frame_file_name(const slam::Scan& scan, size_t index, const std::string& extension) {
  char name[96];
  std::snprintf(name, sizeof name, "frame_%06zu_%" PRId64 ".%s", index, scan.stamp_ns,
                extension.c_str());
  return name;
}

void write_frame(const slam::Scan& scan, const std::string& path, const std::string& format) {
  if (format == "pcd") {
    slam::write_scan_pcd(scan, path);
  } else if (format == "ply") {
    slam::write_scan_ply(scan, path);
  } else {
    slam::write_scan_kitti_bin(scan, path);
  }
}

void run_convert(const ConvertOptions& options, const CliContext& context) {
  const config::Config config = context.load_config();
  std::unique_ptr<slam::ScanSource> source = options.input.open(config);
  std::error_code ec;
  std::filesystem::create_directories(options.output_dir, ec);
  if (ec)
    throw std::runtime_error(options.output_dir + ": cannot create the folder: " + ec.message());

  Progress progress("frames", source->info().frames, context.quiet);
  size_t written = 0;
  while (std::optional<slam::Scan> scan = source->next()) {
    const std::string path = (std::filesystem::path(options.output_dir) /
                              frame_file_name(*scan, written, options.format))
                                 .string();
    write_frame(*scan, path, options.format);
    ++written;
    progress.update(written);
  }
  progress.finish();
  const slam::ReadStats& stats = source->stats();
  for (const auto& warning : stats.warnings) spdlog::warn("{}", warning);
  if (written == 0) throw slam::InputError(source->info().path + ": no readable frame to convert");
  spdlog::info("wrote {} frames as {} to {} ({} skipped, {} warnings)", written, options.format,
               options.output_dir, stats.frames_skipped, stats.warning_count);
}

}  // namespace

Command register_convert(CLI::App& app, const CliContext& context) {
  auto options = std::make_shared<ConvertOptions>();
  CLI::App* command = app.add_subcommand(
      "convert", "Write each frame of a recording as a file (all channels kept)");
  options->input.add_to(*command, /*input_optional=*/false);
  command->add_option("-o,--output", options->output_dir, "Folder for the frame files")->required();
  command
      ->add_option("--format", options->format,
                   "pcd (organized, binary), ply (valid points) or bin (KITTI: x y z intensity)")
      ->check(CLI::IsMember({"pcd", "ply", "bin"}))
      ->capture_default_str();
  return {command, [options, &context] { run_convert(*options, context); }};
}

}  // namespace featsense::app
