#include "procs/registration_server/session_journal.h"

#include "lcmtypes/bounded_decode.h"

namespace orbed::registration {
namespace {

template <class Msg>
bool Decode(const JournalRecord& record, Msg* msg, const SessionJournal::RejectFn& reject) {
  const DecodeResult decoded = DecodeBounded(record.data.data(), record.data.size(), msg);
  if (!decoded.ok() && reject) reject("journal/decode", "a " + record.channel + " record: " + decoded.error);
  return decoded.ok();
}

}  // namespace

SessionJournal::SessionJournal(const std::string& path, RegistrationService* service, RejectFn reject)
    : service_(service), reject_(std::move(reject)), journal_(std::make_unique<Journal>(path)) {
  const JournalContents& contents = journal_->contents();
  for (const JournalRecord& record : contents.records) {
    if (record.channel == kSessionControl) {
      orbed::session_control_t msg;
      if (!Decode(record, &msg, reject_)) continue;
      const int64_t before = service_->changes();
      service_->HandleSessionControl(msg);
      if (service_->changes() != before && msg.command == orbed::session_control_t::START) start_ = msg;
    } else if (record.channel == kAlignmentTrial) {
      orbed::alignment_trial_t msg;
      if (Decode(record, &msg, reject_)) service_->HandleTrial(msg);
    } else if (reject_) {
      reject_("journal/channel", "a record for '" + record.channel + "' in " + path);
    }
  }
  replay_summary_ =
      "journal " + path + ": replayed " + std::to_string(contents.records.size()) + " record(s)";
  if (service_->has_session()) {
    replay_summary_ += ", session '" + service_->session_id() + "' (" +
                       std::to_string(service_->num_trials()) + " trial(s), " +
                       (service_->session_active() ? "active" : "stopped") + ")";
  }
  if (contents.damaged_bytes > 0) {
    const std::string cut = "cut off " + std::to_string(contents.damaged_bytes) + " byte(s) after record " +
                            std::to_string(contents.records.size()) + ": " + contents.damage;
    replay_summary_ += "; " + cut;
    if (reject_) reject_("journal/damaged", "journal " + path + ": " + cut);
  }
}

std::optional<orbed::registration_t> SessionJournal::HandleSessionControl(
    const orbed::session_control_t& msg) {
  const int64_t before = service_->changes();
  const bool was_active = service_->session_active();
  std::optional<orbed::registration_t> out = service_->HandleSessionControl(msg);
  if (service_->changes() == before) return out;
  if (msg.command == orbed::session_control_t::START) {
    start_ = msg;
    Write(true, {MakeJournalRecord(kSessionControl, msg)});
  } else if (msg.command == orbed::session_control_t::RESET && was_active && start_) {
    orbed::session_control_t restamped = *start_;
    restamped.utime = msg.utime;
    Write(true, {MakeJournalRecord(kSessionControl, restamped)});
  } else {
    Write(false, {MakeJournalRecord(kSessionControl, msg)});
  }
  return out;
}

std::optional<orbed::registration_t> SessionJournal::HandleTrial(const orbed::alignment_trial_t& msg) {
  const int64_t before = service_->changes();
  std::optional<orbed::registration_t> out = service_->HandleTrial(msg);
  if (service_->changes() != before) Write(false, {MakeJournalRecord(kAlignmentTrial, msg)});
  return out;
}

void SessionJournal::Write(bool replace, const std::vector<JournalRecord>& records) {
  if (failed_) return;
  if (replace ? journal_->Replace(records) : journal_->Append(records.front())) return;
  failed_ = true;
  if (reject_) reject_("journal/write", journal_->error() + "; the session is no longer journaled");
}

}  // namespace orbed::registration
