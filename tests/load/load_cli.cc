#include "tests/load/load_cli.h"

#include <exception>
#include <fstream>
#include <stdexcept>

#include <CLI/CLI.hpp>

#include "base/command_line.h"
#include "tests/load/load_run.h"

namespace orbed::load {

int RunLoadCli(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  CLI::App app{
      "orbed-load: runs the testbed (scripts/launch/load.yaml; with --arms and --headsets, several of\n"
      "each) at --factor times its nominal rates and measures it: CPU and resident memory of each\n"
      "process, respawns, the drops each process counts on its heartbeat and the kernel's socket\n"
      "drops, per stream the wanted and achieved rates, and each camera's capture-to-receive latency.\n"
      "Run it in a private network namespace (scripts/orbed load and scripts/orbed scale do)."};
  AddVersionFlag(&app);
  LoadOptions options;
  double max_growth_percent = 10;
  app.add_option("--factor", options.factor, "Times the nominal rates, in [0.1, 16]")
      ->check(orbed::NumberIn(kMinFactor, kMaxFactor))
      ->capture_default_str();
  app.add_option(
         "--arms", options.arms,
         "With --headsets: the scale launch (sim/models/scenes/four_arms_or.yaml) with this many arms, "
         "1..4, each an orbed-iiwa-sim --arm a<i>, instead of the single testbed")
      ->check(orbed::NumberIn(1, kMaxScaleArms));
  app.add_option(
         "--headsets", options.headsets,
         "With --arms: this many headsets, 1..8, orbed-hmd --headset h<j> looking at arm a<j mod arms>, "
         "each a different person")
      ->check(orbed::NumberIn(1, kMaxScaleHeadsets));
  std::string json_path;
  app.add_option("--json", json_path,
                 "Also write the report as JSON to this file (scripts/scale.py reads it)");
  app.add_option("--duration-s", options.duration_s, "Length of the run from when every process is ready [s]")
      ->check(orbed::PositiveNumber())
      ->capture_default_str();
  app.add_option("--rss-early-s", options.rss_early_s, "When the early resident-memory sample is taken [s]")
      ->check(orbed::PositiveNumber())
      ->capture_default_str();
  app.add_option("--warmup-s", options.warmup_s,
                 "Rates are accounted from the first heartbeat after this [s]")
      ->check(orbed::NonNegativeNumber())
      ->capture_default_str();
  app.add_option(
         "--max-rss-growth-percent", max_growth_percent,
         "Fail when a process's resident memory grows more than this from the early sample to the end [%]")
      ->check(orbed::NonNegativeNumber())
      ->capture_default_str();
  app.add_option("--ready-timeout-s", options.ready_timeout_s, "Longest wait for the testbed to come up [s]")
      ->check(orbed::PositiveNumber())
      ->capture_default_str();
  app.add_option("--launch-file", options.launch_file, "Launch file (default: scripts/launch/load.yaml)")
      ->check(CLI::ExistingFile);
  app.add_option("--log-dir", options.log_dir, "The testbed's log folder (ORBED_LOG_DIR)")->required();
  app.add_option("--bin-dir", options.bin_dir, "Where orbed-launch is (default: beside orbed-load)");
  if (const auto code = ParseArguments(&app, argc, argv, out, err)) return *code;
  if ((options.arms > 0) != (options.headsets > 0)) {
    err << "orbed-load: --arms and --headsets go together (the scale launch has both)\n";
    return 2;
  }
  try {
    const LoadReport report = RunLoad(options, err);
    out << "\n";
    PrintReport(report, out);
    if (!json_path.empty()) {
      std::ofstream json(json_path);
      json << ReportJson(report) << "\n";
      if (!json) throw std::runtime_error("cannot write " + json_path);
    }
    const auto failures = Failures(report, max_growth_percent);
    for (const auto& failure : failures) err << "orbed-load: FAILED: " << failure << "\n";
    if (failures.empty()) err << "orbed-load: passed\n";
    return failures.empty() ? 0 : 1;
  } catch (const std::exception& e) {
    err << "orbed-load: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace orbed::load
