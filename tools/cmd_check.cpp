// cadclash check: placeholder until the collide narrow phase lands (issue 4).
#include "cli_common.h"

#include <iostream>
#include <memory>

namespace cadclash::cli {

void register_check(CLI::App& app) {
  auto in = std::make_shared<InputOptions>();
  CLI::App* cmd = app.add_subcommand("check", "Report colliding surface pairs");
  add_input_options(*cmd, *in);
  cmd->callback([in] {
    std::cerr << "cadclash check: not built yet\n";
    throw CLI::RuntimeError(kExitUsage);
  });
}

}  // namespace cadclash::cli
