#include "sim/sim_state.h"

#include <filesystem>
#include <stdexcept>

#include "lcmtypes/bounded_decode.h"
#include "lcmtypes/contract/conversions.h"
#include "lcmtypes/contract/validation.h"
#include "runtime/journal.h"

namespace orbed::sim {

std::optional<Eigen::VectorXd> ReadSimState(const std::string& path, const RobotModel& model) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return std::nullopt;
  const auto fail = [&](const std::string& why) -> std::runtime_error {
    return std::runtime_error("state file " + path + ": " + why);
  };
  JournalLimits limits;
  limits.max_file_bytes = 1 << 16;  // one iiwa_status_t of a few joints is a few hundred bytes
  const JournalContents contents = ReadJournal(path, limits);
  if (!contents.damage.empty()) throw fail(contents.damage);
  if (contents.records.size() != 1 || contents.records[0].channel != kSimStateRecord) {
    throw fail("expected one " + std::string(kSimStateRecord) + " record, found " +
               std::to_string(contents.records.size()) + " record(s)" +
               (contents.records.empty() ? "" : " starting with '" + contents.records[0].channel + "'"));
  }
  const JournalRecord& record = contents.records[0];
  orbed::iiwa_status_t status;
  const DecodeResult decoded = DecodeBounded(record.data.data(), record.data.size(), &status);
  if (!decoded.ok()) throw fail(decoded.error);
  std::string why = CheckSize(status.num_joints, model.num_joints(), "num_joints");
  if (why.empty()) why = CheckFinite(status.joint_position_measured, "joint_position_measured");
  if (!why.empty()) throw fail(why);
  const Eigen::VectorXd q = ToVectorX(status.joint_position_measured);
  why = model.ValidateJointVector(q);
  if (!why.empty()) throw fail("joint_position_measured: " + why);
  return q;
}

bool WriteSimState(const std::string& path, const orbed::iiwa_status_t& status, std::string* error) {
  return WriteJournalFile(path, {MakeJournalRecord(kSimStateRecord, status)}, error);
}

}  // namespace orbed::sim
