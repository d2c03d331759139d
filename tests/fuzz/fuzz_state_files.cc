// libFuzzer: the crash-recovery files a respawned process reads (runtime/journal.h): the
// registration server's session journal, the headset's state file and the sim's state file.
//
// The first byte picks the reader (state_records.h). Mode 0 hands the rest to ParseJournal as raw
// file bytes (magic, lengths, checksums). Since a random mutation almost never carries a valid
// checksum, modes 1-3 first make the rest into a well-formed journal (state_records.h), so that
// what the records say is fuzzed; it is written to a scratch file and replayed by
//   1: orbed-registration's SessionJournal into a fresh RegistrationService,
//   2: orbed-hmd's RestoreSession into a fresh HmdSession,
//   3: orbed-iiwa-sim's ReadSimState against the shipped iiwa model.
// Each may refuse by throwing std::exception (or, for the registration journal, by counting
// rejections); a crash, a sanitizer report or unbounded memory is a finding.
#include <cstdint>
#include <string>

#include "base/source_paths.h"
#include "experiments/viraal/registration_service.h"
#include "hmd_emulator/session_file.h"
#include "procs/registration_server/session_journal.h"
#include "runtime/journal.h"
#include "sim/robot_model.h"
#include "sim/sim_state.h"
#include "tests/fuzz/fuzz_files.h"
#include "tests/fuzz/state_records.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  using orbed::fuzz::StateFileMode;
  const int mode = data[0] % 4;
  ++data;
  --size;
  if (mode == StateFileMode::kRawJournal) {
    orbed::ParseJournal(data, size);
    return 0;
  }
  const std::string journal = orbed::fuzz::StateRecordsToJournal(data, size);
  const std::string& path = orbed::fuzz::ScratchFile("state.journal");
  orbed::fuzz::WriteFile(path, reinterpret_cast<const uint8_t*>(journal.data()), journal.size());
  orbed::fuzz::RefuseOrAccept([&] {
    if (mode == StateFileMode::kRegistrationJournal) {
      orbed::registration::RegistrationService service({}, [](const std::string&, const std::string&) {});
      orbed::registration::SessionJournal replay(path, &service,
                                                 [](const std::string&, const std::string&) {});
    } else if (mode == StateFileMode::kHmdStateFile) {
      orbed::hmd::HmdSessionOptions options;
      options.displays_placed = 2;  // as the shipped hmd.yaml places
      orbed::hmd::HmdSession session(options);
      orbed::hmd::RestoreSession(path, &session);
    } else {
      static const auto* model = new orbed::sim::RobotModel(
          orbed::sim::RobotModel::LoadFile(orbed::SourceTreePath("sim/models/iiwa7.urdf")));
      orbed::sim::ReadSimState(path, *model);
    }
  });
  return 0;
}
