#pragma once

// `semap-dataset semantickitti`: S-CSM and S-BKI maps of a SemanticKITTI sequence scored point
// by point against its ground truth, printed as Table IV of Gan et al.
#include <CLI/CLI.hpp>

namespace semap::apps {

// Adds the subcommand (`semantickitti`) to `app`; it runs as the parse's callback and a failure
// leaves as CLI::RuntimeError with the exit status (after its message went to stderr).
void add_kitti_semantic_command(CLI::App& app);

}  // namespace semap::apps
