// The offline trial file and the `mean` command: parsing, line-numbered errors, exit codes, JSON.
#include "procs/registration_server/trial_file.h"

#include <regex>
#include <sstream>

#include <gtest/gtest.h>

#include "procs/registration_server/mean_command.h"

namespace orbed::registration {
namespace {

const std::string kTestData = ORBED_REGISTRATION_TESTDATA;

TEST(TrialFileTest, ParsesTrialsCommentsAndBlankLines) {
  std::istringstream in(
      "# header\n"
      "\n"
      "1,0,0,0,0.1,0.2,0.3\n"
      "  0.7071067811865476 , 0 , 0 , 0.7071067811865476 , -1 , +2 , 3e-3  # quarter turn\n"
      "\t# indented comment\r\n");
  const TrialFile f = ParseTrialFile(in);
  ASSERT_TRUE(f.ok) << f.error;
  ASSERT_EQ(f.quat_WV.size(), 2u);
  EXPECT_EQ(f.line, (std::vector<int>{3, 4}));
  EXPECT_TRUE(f.p_WV[0].isApprox(Eigen::Vector3d(0.1, 0.2, 0.3)));
  EXPECT_TRUE(f.p_WV[1].isApprox(Eigen::Vector3d(-1, 2, 0.003)));
  EXPECT_NEAR(f.quat_WV[1].z(), std::sqrt(0.5), 1e-15);
  EXPECT_EQ(f.normalized, 0);
}

TEST(TrialFileTest, MalformedLinesNameTheLine) {
  struct Case {
    std::string text;
    int line;
    std::string fragment;
  };
  const std::vector<Case> cases = {
      {"1,0,0,0,0,0,0\n1,0,0,0,0,0\n", 2, "found 6 fields"},
      {"1,0,0,0,0,0,0,0\n", 1, "found 8 fields"},
      {"# c\n1,0,0,0,abc,0,0\n", 2, "field 5 (tx) 'abc' is not a number"},
      {"1,0,0,0,0,,0\n", 1, "field 6 (ty) '' is not a number"},
      {"1,0,0,0,0,0,nan\n", 1, "field 7 (tz) is not finite"},
      {"1,0,0,0,0,0,1e999\n", 1, "field 7"},
      {"\n\n2,0,0,0,0,0,0\n", 3, "quaternion norm"},
      {"1,0,0,0,0,0,0 extra\n", 1, "is not a number"},
  };
  for (const Case& c : cases) {
    std::istringstream in(c.text);
    const TrialFile f = ParseTrialFile(in);
    EXPECT_FALSE(f.ok) << c.text;
    EXPECT_EQ(f.error_line, c.line) << c.text;
    EXPECT_NE(f.error.find(c.fragment), std::string::npos) << c.text << " -> " << f.error;
  }
}

TEST(TrialFileTest, SlightlyNonUnitQuaternionIsNormalizedAndCounted) {
  std::istringstream in("1.0002,0,0,0,0,0,0\n");
  const TrialFile f = ParseTrialFile(in);
  ASSERT_TRUE(f.ok) << f.error;
  EXPECT_EQ(f.normalized, 1);
  EXPECT_NEAR(f.max_norm_error, 2e-4, 1e-12);
  EXPECT_DOUBLE_EQ(f.quat_WV[0].w(), 1.0);
}

TEST(MeanCommandTest, MalformedFileExitsTwoNamingTheLine) {
  MeanCommandOptions options;
  options.input_path = kTestData + "/malformed_trials.txt";
  std::ostringstream out, err;
  EXPECT_EQ(RunMeanCommand(options, out, err), 2);
  EXPECT_NE(err.str().find("malformed_trials.txt:5: error: line 5: expected 7"), std::string::npos)
      << err.str();
  EXPECT_TRUE(out.str().empty());
}

TEST(MeanCommandTest, MissingOrEmptyFileExitsTwo) {
  MeanCommandOptions options;
  options.input_path = kTestData + "/no_such_file.txt";
  std::ostringstream out, err;
  EXPECT_EQ(RunMeanCommand(options, out, err), 2);
  EXPECT_NE(err.str().find("cannot open"), std::string::npos);
}

TEST(MeanCommandTest, RobustJsonHasExactlyTheDocumentedShape) {
  MeanCommandOptions options;
  options.input_path = kTestData + "/robust_trials.txt";
  options.robust = true;
  options.json = true;
  std::ostringstream out, err;
  ASSERT_EQ(RunMeanCommand(options, out, err), 0) << err.str();
  const std::string number = R"(-?[0-9.]+(e-?[0-9]+)?)";
  const std::regex shape("\\{\"rotation_wxyz\":\\[" + number + "," + number + "," + number + "," + number +
                         "\\],\"translation_m\":\\[" + number + "," + number + "," + number +
                         "\\],\"converged\":true,\"unique\":true,\"iterations\":[0-9]+,\"n_used\":10,"
                         "\"rejected\":\\[10\\],\"rotation_rms_deg\":" +
                         number + ",\"translation_rms_m\":" + number + "\\}\n");
  EXPECT_TRUE(std::regex_match(out.str(), shape)) << out.str();
  EXPECT_NE(err.str().find("robust_trials.txt:14: note: trial 10 rejected"), std::string::npos) << err.str();
}

TEST(MeanCommandTest, JsonNumbersRoundTrip) {
  geometry::Se3MeanResult r;
  r.q_WV_mean = Eigen::Quaterniond(0.1, 0.2, 0.3, 1.0 / 3.0);
  r.p_WV_mean = Eigen::Vector3d(1e-20, -2.5, 3);
  r.converged = true;
  r.iterations = 4;
  r.dispersion.num_used = 2;
  r.rejected.push_back({7, 0, 0, ""});
  r.rejected.push_back({9, 0, 0, ""});
  r.dispersion.rotation_rms_deg = 0.5;
  r.dispersion.translation_rms_m = 0.004;
  EXPECT_EQ(FormatMeanJson(r),
            "{\"rotation_wxyz\":[0.1,0.2,0.3,0.3333333333333333],\"translation_m\":[1e-20,-2.5,3.0],"
            "\"converged\":true,\"unique\":false,\"iterations\":4,\"n_used\":2,\"rejected\":[7,9],"
            "\"rotation_rms_deg\":0.5,\"translation_rms_m\":0.004}");
}

}  // namespace
}  // namespace orbed::registration
