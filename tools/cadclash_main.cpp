// cadclash — which surfaces of which parts intersect or touch?
#include "check_review.h"
#include "cli_common.h"

int main(int argc, char** argv) {
  CLI::App app{"cadclash: find intersecting and touching surfaces in CAD assemblies and meshes"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "cadclash 0.1.0");
  app.footer("Example: cadclash check assembly.step --json report.json   (cadclash check --help for its options)");
  cadclash::cli::register_info(app);
  cadclash::cli::register_tessellate(app);
  cadclash::cli::register_check(app);
  cadclash::cli::register_approve(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::RuntimeError& e) {
    return e.get_exit_code();  // a subcommand finished with a non-zero code
  } catch (const CLI::Success& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return cadclash::cli::kExitUsage;
  }
  return cadclash::cli::kExitOk;
}
