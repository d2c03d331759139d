/// @file
/// orbed-design: the set-up study's design catalog (experiments/setup/design.h). Commands:
///   catalog [--out FILE] [--urdf FILE]
///         plans the catalog of DefaultDesignSpec() (alignment configurations from
///         experiments/viraal/viraal.yaml) and writes it (stdout, or FILE); the shipped one is
///         `build/bin/orbed-design catalog --out experiments/setup/design.json`, run from the
///         repository (the command is written into the file). Takes about a minute.
///   draw --user-seed S [--targets K] [--design FILE] [--patient NAME]
///         one user's draw as JSON: {"patient", "scene", "pairs": [{"start_id", "target_id",
///         "start_deg", "target_deg", "relation"}]} (scripts/orbed study reads the scene from it).
///   relations [--design FILE] [--targets K] [--users N] [--seed S]
///         how often a (start, target) pair is "same", "mirror" or "mixed" (BendingRelation): over
///         every pair of the catalog (each patient's targets × the starts) and over the draws of N
///         users with seeds S, S+1, ... (JSON).
/// Exit 0; 1 when the catalog cannot be made or a draw is impossible; 2 on bad arguments.
/// Publishes and subscribes nothing.
#include <fstream>
#include <iostream>
#include <map>
#include <string>

#include <CLI/CLI.hpp>

#include "base/command_line.h"
#include "base/json.h"
#include "base/number_list.h"
#include "base/source_paths.h"
#include "experiments/setup/design.h"
#include "experiments/viraal/protocol.h"
#include "sim/robot_model.h"

namespace orbed::setup {
namespace {

void WriteCounts(JsonWriter& j, const std::map<std::string, int>& counts) {
  int total = 0;
  for (const auto& [name, n] : counts) total += n;
  j.BeginObject();
  j.Key("pairs").Int(total);
  for (const char* name : {"same", "mirror", "mixed"}) {
    const auto it = counts.find(name);
    const int n = it == counts.end() ? 0 : it->second;
    j.Key(name).Int(n);
    j.Key(std::string(name) + "_fraction").Number(total ? static_cast<double>(n) / total : 0.0);
  }
  j.EndObject();
}

int Run(int argc, const char* const* argv) {
  CLI::App app{"orbed-design: the set-up study's design catalog and each user's draw from it"};
  AddVersionFlag(&app);
  app.require_subcommand(1);
  std::string out_path, urdf, design, patient;
  uint64_t user_seed = 1, seed = 1;
  int targets = 3, users = 1000;
  auto* catalog = app.add_subcommand("catalog", "plan the catalog (patients, ports, targets, starts)");
  catalog->add_option("--out", out_path, "write it here (default: stdout)");
  catalog->add_option("--urdf", urdf, "robot URDF (default: sim/models/iiwa7.urdf)");
  auto* draw = app.add_subcommand("draw", "one user's patient and (start, target) pairs");
  draw->add_option("--user-seed", user_seed, "the user's seed")->required();
  auto* relations =
      app.add_subcommand("relations", "same / mirror / mixed counts of the catalog and of draws");
  for (CLI::App* sub : {draw, relations}) {
    sub->add_option("--design", design, "the catalog (default: experiments/setup/design.json)");
    sub->add_option("--targets", targets, "K pairs per user")
        ->check(orbed::NumberIn(1, 100))
        ->capture_default_str();
  }
  draw->add_option("--patient", patient, "this patient instead of the drawn one");
  relations->add_option("--users", users, "draws of this many users")
      ->check(orbed::NumberIn(1, 1000000))
      ->capture_default_str();
  relations->add_option("--seed", seed, "the first user's seed")->capture_default_str();
  if (const auto code = ParseArguments(&app, argc, argv, std::cout, std::cerr)) return *code;
  try {
    if (*catalog) {
      std::string command = "orbed-design";
      for (int i = 1; i < argc; ++i) command += std::string(" ") + argv[i];
      DesignSpec spec = DefaultDesignSpec();
      spec.alignment_deg =
          viraal::LoadScenarioFile(SourceTreePath(viraal::kDefaultScenarioRelativePath)).configurations_deg;
      const DesignCatalog c = MakeDesignCatalog(
          spec, urdf.empty() ? SourceTreePath(sim::RobotModel::kDefaultUrdfRelativePath) : urdf,
          SourceTreePath(""), command);
      const std::string text = DesignCatalogJson(c);
      if (out_path.empty()) {
        std::cout << text;
      } else {
        std::ofstream f(out_path);
        f << text;
        if (!f) throw std::runtime_error("cannot write " + out_path);
      }
      for (const CatalogPort& p : c.ports) {
        std::cerr << p.patient << "/" << p.port << ": " << p.branches_kept << " targets (" << p.branches_found
                  << " of " << p.branches_tried << " branches found, " << p.branches_found - p.branches_kept
                  << " dropped by the path rule)\n";
      }
      return 0;
    }
    const DesignCatalog c =
        ReadDesignFile(design.empty() ? SourceTreePath(kDefaultDesignRelativePath) : design);
    JsonWriter j(2);
    if (*draw) {
      const UserDesign d = DrawUserDesign(
          c, user_seed, targets, patient.empty() ? std::nullopt : std::optional<std::string>(patient));
      j.BeginObject();
      j.Key("patient").String(d.patient);
      j.Key("scene").String(d.scene);
      j.Key("pairs").BeginArray();
      for (const DesignPair& p : d.pairs) {
        j.BeginObject();
        j.Key("start_id").String(p.start_id);
        j.Key("target_id").String(p.target_id);
        j.Key("start_deg").Array(p.start_deg);
        j.Key("target_deg").Array(p.target_deg);
        j.Key("relation").String(RelationName(BendingRelation(p.start_deg, p.target_deg)));
        j.EndObject();
      }
      j.EndArray();
      j.EndObject();
    } else {
      std::map<std::string, int> all, drawn;
      for (const CatalogTarget& t : c.targets) {
        for (const CatalogStart& s : c.starts) ++all[RelationName(BendingRelation(s.q_deg, t.q_deg))];
      }
      for (int u = 0; u < users; ++u) {
        for (const DesignPair& p : DrawUserDesign(c, seed + static_cast<uint64_t>(u), targets).pairs)
          ++drawn[RelationName(BendingRelation(p.start_deg, p.target_deg))];
      }
      j.BeginObject();
      j.Key("catalog");
      WriteCounts(j, all);
      j.Key("drawn");
      WriteCounts(j, drawn);
      j.Key("users").Int(users);
      j.Key("targets").Int(targets);
      j.EndObject();
    }
    std::cout << j.str() << "\n";
    return 0;
  } catch (const std::invalid_argument& e) {
    std::cerr << "orbed-design: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "orbed-design: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace
}  // namespace orbed::setup

int main(int argc, char** argv) { return orbed::setup::Run(argc, argv); }
