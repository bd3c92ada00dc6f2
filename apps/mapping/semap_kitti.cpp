// semap-kitti: the KITTI experiments of the semantic map (raw drives, SemanticKITTI), one
// subcommand each.
#include <CLI/CLI.hpp>

#include "kitti_raw_command.hpp"
#include "kitti_semantic_command.hpp"
#include "semap/common/logging.hpp"

int main(int argc, char** argv) {
  CLI::App app{"KITTI raw and SemanticKITTI experiments of the S-BKI / S-CSM semantic map"};
  app.require_subcommand(1);
  semap::apps::add_kitti_raw_command(app);
  semap::apps::add_kitti_semantic_command(app);
  semap::common::setup_logging("warn");
  CLI11_PARSE(app, argc, argv);
  return 0;
}
