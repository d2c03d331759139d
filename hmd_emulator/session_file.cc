#include "hmd_emulator/session_file.h"

#include <stdexcept>
#include <variant>

#include "lcmtypes/bounded_decode.h"
#include "lcmtypes/contract/alignment_trial.h"
#include "runtime/journal.h"

namespace orbed::hmd {
namespace {

constexpr char kStartRecord[] = "SESSION_CONTROL";
constexpr char kTrialRecord[] = "ALIGNMENT_TRIAL";
constexpr int kMaxJoints = 64;

}  // namespace

SavedSession RestoreSession(const std::string& path, HmdSession* session) {
  const auto fail = [&](const std::string& why) {
    return std::runtime_error("state file " + path + ": " + why);
  };
  JournalLimits limits;
  limits.max_file_bytes = 1 << 16;  // a START and one trial: well under a kilobyte
  const JournalContents contents = ReadJournal(path, limits);
  if (!contents.damage.empty()) throw fail(contents.damage);
  const auto& records = contents.records;
  SavedSession saved;
  if (records.empty()) return saved;
  if (records.size() > 2 || records[0].channel != kStartRecord ||
      (records.size() == 2 && records[1].channel != kTrialRecord)) {
    throw fail("expected a SESSION_CONTROL record and at most one ALIGNMENT_TRIAL record");
  }
  orbed::session_control_t start;
  DecodeResult decoded = DecodeBounded(records[0].data.data(), records[0].data.size(), &start);
  if (!decoded.ok()) throw fail(decoded.error);
  if (start.command != orbed::session_control_t::START)
    throw fail("the SESSION_CONTROL record is not a START");
  const SessionDecision decision = session->Handle(start, RobotKnown{});
  if (decision.kind != SessionDecision::Kind::kStart) throw fail("START refused: " + decision.refusal.reason);
  saved.start = start;
  if (records.size() == 2) {
    orbed::alignment_trial_t trial;
    decoded = DecodeBounded(records[1].data.data(), records[1].data.size(), &trial);
    if (!decoded.ok()) throw fail(decoded.error);
    const auto checked = CheckAlignmentTrial(trial, kMaxJoints);
    if (const auto* refusal = std::get_if<Refusal>(&checked))
      throw fail("ALIGNMENT_TRIAL: " + refusal->reason);
    if (!session->ObserveTrial(trial)) {
      throw fail("trial " + std::to_string(trial.trial_index) + " of '" + trial.session_id +
                 "' is not one of " + session->state().Describe());
    }
    session->RecordTrial(trial);  // a retry of its request gets this trial again, not a new one
    saved.last_trial = trial;
  }
  return saved;
}

bool SaveSession(const std::string& path, const SavedSession& saved, std::string* error) {
  std::vector<JournalRecord> records;
  if (saved.start) records.push_back(MakeJournalRecord(kStartRecord, *saved.start));
  if (saved.start && saved.last_trial) records.push_back(MakeJournalRecord(kTrialRecord, *saved.last_trial));
  return WriteJournalFile(path, records, error);
}

}  // namespace orbed::hmd
