# hmd_user_lib: the headset wearer's engines (no LCM): head trajectory, SLAM error model, the
# emulated ViRAAl user, one emulated trial end to end, and the statistics used to compare modes.
# Configs with documented defaults: hmd_emulator/config/{slam,user,viraal_walk}.yaml.
add_library(hmd_user_lib
  ${CMAKE_CURRENT_LIST_DIR}/yaml_fields.cc
  ${CMAKE_CURRENT_LIST_DIR}/head_trajectory.cc
  ${CMAKE_CURRENT_LIST_DIR}/slam_model.cc
  ${CMAKE_CURRENT_LIST_DIR}/user_model.cc
  ${CMAKE_CURRENT_LIST_DIR}/viraal_trial.cc
  ${CMAKE_CURRENT_LIST_DIR}/user_study.cc
  ${CMAKE_CURRENT_LIST_DIR}/stats.cc)
target_include_directories(hmd_user_lib PUBLIC ${PROJECT_SOURCE_DIR})
target_link_libraries(hmd_user_lib PUBLIC Eigen3::Eigen yaml-cpp orbed_robot_model)

# hmd-user-study: the emulated study's statistics per display mode (next to the paper's Table 1).
add_executable(hmd-user-study ${CMAKE_CURRENT_LIST_DIR}/user_study_main.cc)
target_link_libraries(hmd-user-study PRIVATE hmd_user_lib registration_lib)

orbed_add_gtest(NAME hmd_stats_test SRCS ${CMAKE_CURRENT_LIST_DIR}/stats_test.cc LIBS hmd_user_lib TIMEOUT 60)
orbed_add_gtest(NAME hmd_slam_model_test SRCS ${CMAKE_CURRENT_LIST_DIR}/slam_model_test.cc
                LIBS hmd_user_lib orbed_lcmtypes TIMEOUT 60)
add_dependencies(hmd_slam_model_test orbed_lcmtypes_gen)
orbed_add_gtest(NAME hmd_user_model_test SRCS ${CMAKE_CURRENT_LIST_DIR}/user_model_test.cc LIBS hmd_user_lib
                TIMEOUT 120)
