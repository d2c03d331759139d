#pragma once
/// @file
/// The paper's figures for the robot set-up study, in one place: Fotouhi et al., RA-L 2020, Sec.
/// IV-B, Tables 2-4 (8 users, 3 guidance modes in randomized order, 3 targets each). Table 2: joint
/// errors over all joints [deg]; Table 3: p-values per joint (the paper lists joints 1-6) and in
/// total, the test not named; Table 4: execution and ViRAAl alignment times [s] (the paper gives
/// min:s).
namespace orbed::study {

struct PaperStats {
  double mean, median, min, max, std;
};

inline constexpr const char* kSetupModes[] = {"ar_reflective", "ar", "fixed"};

/// Table 2, in kSetupModes order [deg].
inline constexpr PaperStats kPaperTable2[] = {
    {23.7, 4.93, 0.02, 188, 41.1}, {26.8, 5.88, 0.00, 197, 42.4}, {71.4, 50.6, 0.64, 249, 61.8}};

/// Table 3: the pairs, and per pair joints 1-6 then the total.
inline constexpr const char* kSetupPairs[] = {"ar_reflective/ar", "ar_reflective/fixed", "ar/fixed"};
inline constexpr double kPaperTable3[3][7] = {{0.61, 0.50, 0.23, 0.71, 0.59, 0.27, 0.54},
                                              {1.2e-7, 1.5e-2, 2.4e-7, 0.77, 2.2e-7, 7.6e-5, 1.2e-16},
                                              {1.6e-7, 3.9e-2, 6.2e-5, 0.87, 1.2e-7, 5.8e-8, 2.0e-18}};

/// Table 4 [s]: execution time per mode; alignment time for the two headset modes (none for fixed).
inline constexpr PaperStats kPaperExecution[] = {
    {120, 110, 39, 227, 50}, {91, 83, 22, 306, 59}, {94, 95, 27, 200, 48}};
inline constexpr PaperStats kPaperAlignment[] = {{272, 282, 126, 419, 101}, {149, 112, 71, 266, 72}};

inline constexpr char kPaperSetupSource[] =
    "Fotouhi et al., RA-L 2020, Sec. IV-B, Tables 2-4 (8 users x 3 modes x 3 targets)";

}  // namespace orbed::study
