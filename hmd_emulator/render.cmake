# hmd_render_lib: what the headset's camera and displays show (engines, no LCM).
#   scene_geometry  world-frame primitives of the OR scene, the real robot (X_WR) and the virtual one
#                   (X_WV), per-link bodies and colours; tessellation into triangles
#   renderer        z-buffered software rasteriser (Lambert-shaded BGR, depth, body ids), hologram
#                   overlay, JPEG coding
#   gaze            analytic ray casting (box, cylinder, sphere, capsule) for the gaze hit
#   reflective      reflective-AR display (paper Sec. II-B) and AR view compositing
add_library(hmd_render_lib
  ${CMAKE_CURRENT_LIST_DIR}/scene_geometry.cc
  ${CMAKE_CURRENT_LIST_DIR}/renderer.cc
  ${CMAKE_CURRENT_LIST_DIR}/gaze.cc
  ${CMAKE_CURRENT_LIST_DIR}/reflective.cc)
target_include_directories(hmd_render_lib PUBLIC ${PROJECT_SOURCE_DIR})
target_link_libraries(hmd_render_lib PUBLIC orbed_robot_model Eigen3::Eigen opencv_core
                      opencv_imgproc opencv_imgcodecs)

orbed_add_gtest(NAME camera_model_test SRCS ${CMAKE_CURRENT_LIST_DIR}/camera_model_test.cc
                LIBS hmd_render_lib)
orbed_add_gtest(NAME renderer_test SRCS ${CMAKE_CURRENT_LIST_DIR}/renderer_test.cc
                LIBS hmd_render_lib)
orbed_add_gtest(NAME gaze_test SRCS ${CMAKE_CURRENT_LIST_DIR}/gaze_test.cc LIBS hmd_render_lib)
orbed_add_gtest(NAME reflective_test SRCS ${CMAKE_CURRENT_LIST_DIR}/reflective_test.cc
                LIBS hmd_render_lib)

# Writes docs/images/camera_frame.png and reflective_view.png (the README's pictures).
orbed_add_process(NAME orbed-render-snapshot MAIN ${CMAKE_CURRENT_LIST_DIR}/render_snapshot_main.cc
                  LIBS hmd_render_lib)
