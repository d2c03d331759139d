/// @file
/// orbed-registration: the registration server and its offline command line.
///
///   orbed-registration mean --input FILE [--robust] [--json] [--model-centroid-m X Y Z]
///     Offline SE(3) mean of the trials in FILE (one `qw,qx,qy,qz,tx,ty,tz` per line, '#'
///     comments); see mean_command.h for the output and exit codes. Touches no network.
///
///   orbed-registration            (no subcommand)
///     The LCM server process (DESIGN.md §4): subscribes SESSION_CONTROL, ALIGNMENT_TRIAL,
///     LANDMARK_REQUEST, MISALIGNMENT_REQUEST; publishes REGISTRATION (per trial and 1 Hz),
///     LANDMARK, MISALIGNMENT, PROCESS_STATUS. Not wired in this build yet.
///
/// All logic lives in registration_lib; this file only parses flags.

#include <iostream>
#include <vector>

#include <CLI/CLI.hpp>

#include "mean_command.h"

int main(int argc, char** argv) {
  CLI::App app{"orbed-registration: SE(3) averaging of alignment trials, landmark triangulation and "
               "misalignment evaluation"};
  app.require_subcommand(0, 1);

  orbed::registration::MeanCommandOptions mean_options;
  std::vector<double> centroid_m;
  CLI::App* mean = app.add_subcommand("mean", "Offline SE(3) mean of a trial file (qw,qx,qy,qz,tx,ty,tz per line)");
  mean->add_option("--input", mean_options.input_path, "Trial file, one qw,qx,qy,qz,tx,ty,tz per line; '-' = stdin")
      ->required();
  mean->add_flag("--robust", mean_options.robust,
                 "Reject outlying trials (L1 median + k*MAD) before the Karcher mean");
  mean->add_flag("--json", mean_options.json, "Print one JSON object instead of a text report");
  mean->add_option("--model-centroid-m", centroid_m,
                   "Average translations about this model centroid p_VC (3 numbers, metres, in V)")
      ->expected(3);

  CLI11_PARSE(app, argc, argv);

  if (mean->parsed()) {
    if (centroid_m.size() == 3) mean_options.p_VC = Eigen::Vector3d(centroid_m[0], centroid_m[1], centroid_m[2]);
    return orbed::registration::RunMeanCommand(mean_options, std::cout, std::cerr);
  }
  std::cerr << "orbed-registration: the LCM server is not built into this binary yet; use the `mean` "
               "subcommand (see --help)\n";
  return 1;
}
