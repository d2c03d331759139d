// The registration server's session journal (session_journal.h): a server stopped anywhere in a
// session and restarted on its journal answers the rest of the session with the same REGISTRATION
// bytes as one that never stopped; damaged journals are cut at the damage and reported; the
// journal stays bounded however the session is driven.
#include "procs/registration_server/session_journal.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "base/units.h"
#include "lcmtypes/contract/conversions.h"

namespace orbed::registration {
namespace {

namespace fs = std::filesystem;
using SC = orbed::session_control_t;

std::string TempPath(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("orbed_session_journal_test_" + std::to_string(getpid()));
  fs::create_directories(dir);
  fs::remove(dir / name);
  return (dir / name).string();
}

SC Control(int8_t command, const std::string& id, int64_t utime) {
  SC msg{};
  msg.utime = utime;
  msg.session_id = id;
  msg.command = command;
  msg.display_mode = orbed::alignment_trial_t::MODE_AR_REFLECTIVE;
  msg.num_mirrors = 1;
  msg.method = orbed::registration_t::METHOD_ROBUST;
  return msg;
}

orbed::alignment_trial_t Trial(const std::string& id, int index, int64_t utime) {
  orbed::alignment_trial_t msg{};
  msg.utime = utime;
  msg.session_id = id;
  msg.trial_index = index;
  msg.display_mode = orbed::alignment_trial_t::MODE_AR_REFLECTIVE;
  msg.num_mirrors = 1;
  msg.num_joints = 7;
  msg.joint_position.assign(7, 0.1 * index);
  Eigen::Isometry3d X_WV = Eigen::Isometry3d::Identity();
  const double angle_deg = index == 4 ? 90.0 : 2.0 * std::sin(index);  // trial 4 an outlier
  X_WV.linear() =
      Eigen::AngleAxisd(angle_deg * kDegToRad, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  X_WV.translation() = Eigen::Vector3d(0.01 * index, -0.5, 1.0 + 0.003 * index * index);
  msg.X_WV = ToPose(X_WV);
  msg.duration_s = 10.0 + index;
  msg.user_id = "emulated-1";
  return msg;
}

// A session's inputs in order: a START of another session, the session, trials, a RESET, more
// trials (one refused as a duplicate), COMPUTE, STOP, COMPUTE again.
struct Input {
  std::optional<SC> control;
  std::optional<orbed::alignment_trial_t> trial;
};
std::vector<Input> Session() {
  std::vector<Input> in;
  in.push_back({Control(SC::START, "earlier", 1), {}});
  in.push_back({{}, Trial("earlier", 0, 2)});
  in.push_back({Control(SC::START, "s", 10), {}});
  for (int i = 0; i < 3; ++i) in.push_back({{}, Trial("s", i, 20 + i)});
  in.push_back({Control(SC::RESET, "s", 30), {}});
  for (int i = 0; i < 6; ++i) in.push_back({{}, Trial("s", i, 40 + i)});
  in.push_back({{}, Trial("s", 2, 50)});  // a duplicate index: refused
  in.push_back({Control(SC::COMPUTE, "s", 60), {}});
  in.push_back({Control(SC::STOP, "s", 70), {}});
  in.push_back({Control(SC::COMPUTE, "s", 80), {}});
  return in;
}

template <class Msg>
std::vector<uint8_t> Bytes(const Msg& msg) {
  std::vector<uint8_t> bytes(msg.getEncodedSize());
  msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

// What a server answers to each input from `first` on: its REGISTRATION bytes (empty when none)
// followed by the periodic state's bytes.
struct Server {
  std::map<std::string, int> rejections;
  RegistrationService service{RegistrationServiceOptions{},
                              [this](const std::string& key, const std::string&) { ++rejections[key]; }};
  std::unique_ptr<SessionJournal> journal;

  explicit Server(const std::string& path) {
    if (!path.empty()) {
      journal = std::make_unique<SessionJournal>(
          path, &service, [this](const std::string& key, const std::string&) { ++rejections[key]; });
    }
  }
  std::vector<std::vector<uint8_t>> Feed(const std::vector<Input>& inputs, size_t first, size_t last) {
    std::vector<std::vector<uint8_t>> out;
    for (size_t i = first; i < last; ++i) {
      std::optional<orbed::registration_t> answer;
      if (inputs[i].control) {
        answer = journal ? journal->HandleSessionControl(*inputs[i].control)
                         : service.HandleSessionControl(*inputs[i].control);
      } else {
        answer = journal ? journal->HandleTrial(*inputs[i].trial) : service.HandleTrial(*inputs[i].trial);
      }
      out.push_back(answer ? Bytes(*answer) : std::vector<uint8_t>{});
      const auto periodic = service.PeriodicState();
      out.push_back(periodic ? Bytes(*periodic) : std::vector<uint8_t>{});
    }
    return out;
  }
};

TEST(SessionJournal, ARestartAnywhereAnswersTheRestOfTheSessionByteForByte) {
  const std::vector<Input> inputs = Session();
  Server uninterrupted("");
  const auto expected = uninterrupted.Feed(inputs, 0, inputs.size());
  ASSERT_FALSE(expected[2 * 14].empty());  // the COMPUTE answer: a robust mean with the outlier
  for (size_t kill = 0; kill <= inputs.size(); ++kill) {
    const std::string path = TempPath("restart.journal");
    std::vector<std::vector<uint8_t>> got;
    {
      Server before(path);
      got = before.Feed(inputs, 0, kill);
    }  // the process dies: only the journal remains
    Server after(path);
    const auto rest = after.Feed(inputs, kill, inputs.size());
    got.insert(got.end(), rest.begin(), rest.end());
    ASSERT_EQ(got.size(), expected.size());
    for (size_t i = 0; i < got.size(); ++i)
      EXPECT_EQ(got[i], expected[i]) << "killed before input " << kill << ", output " << i;
    EXPECT_EQ(after.rejections.count("journal/damaged"), 0u);
  }
}

TEST(SessionJournal, ATornRecordIsCutAndTheWholeRecordsStillCount) {
  const std::vector<Input> inputs = Session();
  const std::string path = TempPath("torn.journal");
  {
    Server before(path);
    before.Feed(inputs, 0, 6);  // START earlier, its trial, START s, trials 0..2
  }
  const auto whole_size = fs::file_size(path);
  {
    std::ofstream(path, std::ios::binary | std::ios::app) << std::string("ORJ1\0\0\0\x0f", 8);  // torn
  }
  Server after(path);
  EXPECT_EQ(after.rejections["journal/damaged"], 1);
  EXPECT_EQ(fs::file_size(path), whole_size);  // cut off before appending
  EXPECT_EQ(after.service.session_id(), "s");
  EXPECT_EQ(after.service.num_trials(), 3);
  EXPECT_NE(after.journal->replay_summary().find("cut off 8 byte(s)"), std::string::npos)
      << after.journal->replay_summary();
}

TEST(SessionJournal, DamagedUndecodableAndForeignRecordsAreRefused) {
  // A flipped byte inside the second record: only the START is replayed.
  const std::string path = TempPath("damaged.journal");
  {
    Server before(path);
    before.Feed(Session(), 2, 5);  // START s, trials 0 and 1
  }
  std::string bytes;
  {
    std::ifstream in(path, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  const size_t second = bytes.find("ORJ1", 4);
  ASSERT_NE(second, std::string::npos);
  bytes[second + 40] = static_cast<char>(bytes[second + 40] ^ 0x01);
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
  {
    Server after(path);
    EXPECT_EQ(after.rejections["journal/damaged"], 1);
    EXPECT_EQ(after.service.num_trials(), 0);
    EXPECT_TRUE(after.service.session_active());
  }
  // Records that pass the checksum but are not what they say, or not for this server.
  std::string error;
  ASSERT_TRUE(WriteJournalFile(path,
                               {MakeJournalRecord("SESSION_CONTROL", Control(SC::START, "s", 1)),
                                JournalRecord{"ALIGNMENT_TRIAL", {1, 2, 3}},
                                MakeJournalRecord("IIWA_COMMAND", Control(SC::STOP, "s", 2)),
                                MakeJournalRecord("ALIGNMENT_TRIAL", Trial("other", 0, 3)),
                                MakeJournalRecord("ALIGNMENT_TRIAL", Trial("s", 0, 4))},
                               &error))
      << error;
  Server after(path);
  EXPECT_EQ(after.rejections["journal/decode"], 1);
  EXPECT_EQ(after.rejections["journal/channel"], 1);
  EXPECT_EQ(after.rejections["ALIGNMENT_TRIAL/session"], 1);  // the service's own check
  EXPECT_EQ(after.service.num_trials(), 1);
  EXPECT_TRUE(after.service.session_active());
}

TEST(SessionJournal, StaysBoundedWhateverTheSessionSees) {
  const std::string path = TempPath("bounded.journal");
  Server server(path);
  server.journal->HandleSessionControl(Control(SC::START, "s", 1));
  int64_t utime = 2;
  for (int round = 0; round < 500; ++round) {
    server.journal->HandleTrial(Trial("s", 0, utime++));
    server.journal->HandleTrial(Trial("s", 1, utime++));
    server.journal->HandleSessionControl(Control(SC::RESET, "s", utime++));
    server.journal->HandleSessionControl(Control(SC::RESET, "s", utime++));  // nothing to reset
  }
  server.journal->HandleTrial(Trial("s", 0, utime++));
  for (int i = 0; i < 500; ++i) server.journal->HandleSessionControl(Control(SC::STOP, "s", utime++));
  server.journal->HandleSessionControl(Control(SC::RESET, "s", utime++));
  for (int i = 0; i < 500; ++i) server.journal->HandleSessionControl(Control(SC::RESET, "s", utime++));
  // START (re-stamped by the last active RESET), trial 0, STOP, RESET.
  EXPECT_EQ(ReadJournal(path).records.size(), 4u);
  const auto periodic = server.service.PeriodicState();
  Server again(path);
  EXPECT_EQ(Bytes(*again.service.PeriodicState()), Bytes(*periodic));
}

}  // namespace
}  // namespace orbed::registration
