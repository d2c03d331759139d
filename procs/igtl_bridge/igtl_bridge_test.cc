// orbed-igtl-bridge's messages and server against the OpenIGTLink library itself (the oracle: its
// own Unpack with CRC check reads what the bridge packs, and packs what the bridge reads):
//   - TRANSFORM: metres → millimetres, the rotation as is; POSITION's (x, y, z, w) quaternion;
//   - IMAGE: dimensions, RGB order, spacing 1000 / fx mm, the plane 1 m in front of the camera;
//   - STATUS and STRING: code, names and text;
//   - the reader: a byte at a time; a flipped body byte fails the CRC; other types skipped; a
//     claimed 2^40-byte body ends the stream; non-rigid matrices and non-ASCII names refused;
//   - the server on 127.0.0.1 (an ephemeral port) with the library's ClientSocket: both
//     directions, the client limit, a departure;
//   - RobotFrames: the flange at the KUKA data sheet's 1.266 m above the base at q = 0.
#include "procs/igtl_bridge/igtl_bridge_process.h"

#include <chrono>
#include <cmath>
#include <cstring>
#include <thread>

#include <gtest/gtest.h>
#include <igtlClientSocket.h>
#include <igtlImageMessage.h>
#include <igtlMessageHeader.h>
#include <igtlPositionMessage.h>
#include <igtlStatusMessage.h>
#include <igtlStringMessage.h>
#include <igtlTransformMessage.h>

#include "base/source_paths.h"
#include "procs/igtl_bridge/igtl_bridge.h"
#include "procs/igtl_bridge/igtl_server.h"

namespace orbed::igtl_bridge {
namespace {

Eigen::Isometry3d SomePose() {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  X.translation() = Eigen::Vector3d(0.25, -1.5, 0.875);
  return X;
}

// Unpacks `bytes` with the library into `msg` (a New() of the right type); returns Unpack's flags.
template <class Pointer>
int LibraryUnpack(const std::vector<uint8_t>& bytes, Pointer& msg, std::string* type = nullptr) {
  igtl::MessageHeader::Pointer header = igtl::MessageHeader::New();
  header->InitPack();
  std::memcpy(header->GetPackPointer(), bytes.data(), header->GetPackSize());
  header->Unpack();
  if (type) *type = header->GetDeviceType();
  msg->SetMessageHeader(header);
  msg->AllocatePack();
  EXPECT_EQ(static_cast<size_t>(header->GetPackSize() + msg->GetPackBodySize()), bytes.size());
  std::memcpy(msg->GetPackBodyPointer(), bytes.data() + header->GetPackSize(), msg->GetPackBodySize());
  return msg->Unpack(1);
}

std::vector<uint8_t> LibraryTransform(const std::string& device, const igtl::Matrix4x4& m) {
  igtl::TransformMessage::Pointer msg = igtl::TransformMessage::New();
  msg->SetDeviceName(device.c_str());
  igtl::Matrix4x4 copy;
  std::memcpy(copy, m, sizeof(copy));
  msg->SetMatrix(copy);
  msg->Pack();
  const auto* p = static_cast<const uint8_t*>(msg->GetPackPointer());
  return std::vector<uint8_t>(p, p + msg->GetPackSize());
}

void ToMatrix(const Eigen::Isometry3d& X_m, igtl::Matrix4x4& m) {
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c)
      m[r][c] = static_cast<float>(X_m.matrix()(r, c) * (c == 3 && r < 3 ? 1000.0 : 1.0));
}

TEST(IgtlCodec, TransformInMillimetresReadByTheLibrary) {
  const Eigen::Isometry3d X = SomePose();
  const std::vector<uint8_t> bytes = PackTransform("iiwa_link_4", X, 1'700'000'000'250'000);
  igtl::TransformMessage::Pointer msg = igtl::TransformMessage::New();
  std::string type;
  ASSERT_TRUE(LibraryUnpack(bytes, msg, &type) & igtl::MessageHeader::UNPACK_BODY);  // CRC checked
  EXPECT_EQ(type, "TRANSFORM");
  EXPECT_STREQ(msg->GetDeviceName(), "iiwa_link_4");
  igtl::Matrix4x4 m;
  msg->GetMatrix(m);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(m[r][c], X.linear()(r, c), 1e-6);
    EXPECT_NEAR(m[r][3], X.translation()(r) * 1000.0, 1e-3);  // 250 mm, -1500 mm, 875 mm
  }
  unsigned int sec = 0, frac = 0;
  msg->GetTimeStamp(&sec, &frac);
  EXPECT_EQ(sec, 1'700'000'000u);
  EXPECT_THROW(PackTransform("a_name_of_21_bytes___", X, 0), std::invalid_argument);
}

TEST(IgtlCodec, ImageStatusAndStringReadByTheLibrary) {
  cv::Mat bgr(2, 3, CV_8UC3);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 3; ++x) bgr.at<cv::Vec3b>(y, x) = cv::Vec3b(10 * x, 100 + y, 200);  // B, G, R
  const Eigen::Isometry3d X_WC = SomePose();
  igtl::ImageMessage::Pointer image = igtl::ImageMessage::New();
  ASSERT_TRUE(LibraryUnpack(PackImage("HMDCamera", bgr, X_WC, 500.0, 0), image) &
              igtl::MessageHeader::UNPACK_BODY);
  int size[3];
  float spacing[3];
  image->GetDimensions(size);
  image->GetSpacing(spacing);
  EXPECT_EQ(size[0], 3);
  EXPECT_EQ(size[1], 2);
  EXPECT_EQ(size[2], 1);
  EXPECT_FLOAT_EQ(spacing[0], 2.0f);  // 1000 mm / 500 px
  EXPECT_EQ(image->GetNumComponents(), 3);
  EXPECT_EQ(image->GetScalarType(), igtl::ImageMessage::TYPE_UINT8);
  const auto* rgb = static_cast<const uint8_t*>(image->GetScalarPointer());
  // Pixel (x = 2, y = 1): R 200, G 101, B 20.
  EXPECT_EQ(rgb[(1 * 3 + 2) * 3 + 0], 200);
  EXPECT_EQ(rgb[(1 * 3 + 2) * 3 + 1], 101);
  EXPECT_EQ(rgb[(1 * 3 + 2) * 3 + 2], 20);
  igtl::Matrix4x4 m;
  image->GetMatrix(m);
  const Eigen::Vector3d centre_mm = (X_WC.translation() + X_WC.linear().col(2)) * 1000.0;
  for (int r = 0; r < 3; ++r) EXPECT_NEAR(m[r][3], centre_mm(r), 1e-2);

  igtl::StatusMessage::Pointer status = igtl::StatusMessage::New();
  ASSERT_TRUE(
      LibraryUnpack(PackStatus("orbed-iiwa-sim", igtl::StatusMessage::STATUS_OK, "RUNNING", "in 3", 0),
                    status) &
      igtl::MessageHeader::UNPACK_BODY);
  EXPECT_STREQ(status->GetDeviceName(), "orbed-iiwa-sim");
  EXPECT_EQ(status->GetCode(), igtl::StatusMessage::STATUS_OK);
  EXPECT_STREQ(status->GetErrorName(), "RUNNING");
  EXPECT_STREQ(status->GetStatusString(), "in 3");

  igtl::StringMessage::Pointer text = igtl::StringMessage::New();
  ASSERT_TRUE(LibraryUnpack(PackString("Events", "SESSION_CONTROL START s1", 0), text) &
              igtl::MessageHeader::UNPACK_BODY);
  EXPECT_STREQ(text->GetString(), "SESSION_CONTROL START s1");
}

TEST(IgtlCodec, ReaderTakesTransformsAndPositionsAByteAtATime) {
  const Eigen::Isometry3d X = SomePose();
  igtl::Matrix4x4 m;
  ToMatrix(X, m);
  std::vector<uint8_t> stream = LibraryTransform("Target", m);
  igtl::PositionMessage::Pointer position = igtl::PositionMessage::New();
  position->SetDeviceName("Needle");
  position->SetPackType(igtl::PositionMessage::ALL);
  position->SetPosition(10.0f, -20.0f, 30.0f);
  const float q_xyzw[4] = {0.0f, 0.0f, std::sin(0.25f), std::cos(0.25f)};  // 0.5 rad about z
  position->SetQuaternion(q_xyzw);
  position->Pack();
  const auto* p = static_cast<const uint8_t*>(position->GetPackPointer());
  stream.insert(stream.end(), p, p + position->GetPackSize());

  IgtlReader reader;
  std::vector<IgtlPose> poses;
  for (uint8_t byte : stream) {
    reader.Feed(&byte, 1);
    IgtlPose pose;
    std::string reason;
    for (IgtlReader::Result r; (r = reader.Next(&pose, &reason)) != IgtlReader::Result::kNeedMore;) {
      ASSERT_EQ(r, IgtlReader::Result::kPose) << reason;
      poses.push_back(pose);
    }
  }
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_EQ(poses[0].type, "TRANSFORM");
  EXPECT_EQ(poses[0].device, "Target");
  EXPECT_TRUE(poses[0].X_m.isApprox(X, 1e-6)) << poses[0].X_m.matrix();
  EXPECT_EQ(poses[1].type, "POSITION");
  EXPECT_EQ(poses[1].device, "Needle");
  EXPECT_TRUE(poses[1].X_m.translation().isApprox(Eigen::Vector3d(0.01, -0.02, 0.03), 1e-6));
  EXPECT_NEAR(Eigen::AngleAxisd(poses[1].X_m.linear()).angle(), 0.5, 1e-6);
  EXPECT_NEAR(poses[1].X_m.linear()(1, 0), std::sin(0.5), 1e-6);  // about +z
  EXPECT_EQ(reader.buffered(), 0u);
}

TEST(IgtlCodec, ReaderRefusesAndSkipsWhatItShould) {
  const auto next = [](IgtlReader& reader, const std::vector<uint8_t>& bytes, std::string* reason) {
    reader.Feed(bytes.data(), bytes.size());
    IgtlPose pose;
    return reader.Next(&pose, reason);
  };
  igtl::Matrix4x4 m;
  ToMatrix(SomePose(), m);
  IgtlReader reader;
  std::string reason;
  // A flipped body byte: the library's CRC check fails.
  std::vector<uint8_t> bad_crc = LibraryTransform("Target", m);
  bad_crc[kHeaderBytes + 5] ^= 0x40;
  EXPECT_EQ(next(reader, bad_crc, &reason), IgtlReader::Result::kRefused);
  EXPECT_NE(reason.find("CRC"), std::string::npos) << reason;
  // A matrix that is not a rotation (scaled by 2).
  igtl::Matrix4x4 scaled;
  ToMatrix(SomePose(), scaled);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) scaled[r][c] *= 2;
  EXPECT_EQ(next(reader, LibraryTransform("Target", scaled), &reason), IgtlReader::Result::kRefused);
  EXPECT_NE(reason.find("not a rotation"), std::string::npos) << reason;
  // A device name that is not ASCII.
  EXPECT_EQ(next(reader, LibraryTransform("caf\xc3\xa9", m), &reason), IgtlReader::Result::kRefused);
  // Another type: skipped, and the stream goes on.
  EXPECT_EQ(next(reader, PackStatus("x", 1, "OK", "fine", 0), &reason), IgtlReader::Result::kSkipped);
  EXPECT_EQ(reason, "type STATUS");
  EXPECT_EQ(next(reader, LibraryTransform("Target", m), &reason), IgtlReader::Result::kPose);
  // A header claiming a 2^40-byte body ends the stream before anything is allocated for it.
  std::vector<uint8_t> huge = LibraryTransform("Target", m);
  huge.resize(kHeaderBytes);
  for (int i = 0; i < 8; ++i) huge[42 + i] = i == 2 ? 1 : 0;  // body size 2^40, big-endian
  EXPECT_EQ(next(reader, huge, &reason), IgtlReader::Result::kFatal);
  EXPECT_NE(reason.find("1099511627776 bytes"), std::string::npos) << reason;
  EXPECT_LE(reader.buffered(), kHeaderBytes);
  EXPECT_EQ(next(reader, LibraryTransform("Target", m), &reason),
            IgtlReader::Result::kFatal);  // stays closed
}

// Polls `server` until `done` or 5 s of wall time (the client side is the library's blocking socket).
template <class Done>
bool PollUntil(IgtlServer& server, std::vector<IgtlPose>* poses, std::vector<IgtlEvent>* events, Done done) {
  for (int i = 0; i < 5000 && !done(); ++i) {
    server.Poll([&](const IgtlPose& p, const std::string&) { poses->push_back(p); },
                [&](const IgtlEvent& e) { events->push_back(e); });
    if (!done()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return done();
}

TEST(IgtlServer, BothDirectionsWithTheLibrarysClientSocket) {
  IgtlServerOptions options;
  options.port = 0;
  options.max_clients = 1;
  IgtlServer server(options);
  ASSERT_GT(server.port(), 0);
  igtl::ClientSocket::Pointer client = igtl::ClientSocket::New();
  ASSERT_EQ(client->ConnectToServer("127.0.0.1", server.port()), 0);
  std::vector<IgtlPose> poses;
  std::vector<IgtlEvent> events;
  ASSERT_TRUE(PollUntil(server, &poses, &events, [&] { return server.num_clients() == 1; }));
  EXPECT_EQ(events.at(0).kind, IgtlEvent::kConnected);

  // Server → client: the library reads the bridge's TRANSFORM with its CRC.
  const Eigen::Isometry3d X = SomePose();
  EXPECT_EQ(server.Broadcast(PackTransform("RobotBase", X, 0)), 0);
  server.Poll([](const IgtlPose&, const std::string&) {}, [](const IgtlEvent&) {});
  client->SetReceiveTimeout(5000);
  igtl::MessageHeader::Pointer header = igtl::MessageHeader::New();
  header->InitPack();
  ASSERT_EQ(client->Receive(header->GetPackPointer(), header->GetPackSize()), header->GetPackSize());
  header->Unpack();
  EXPECT_STREQ(header->GetDeviceType(), "TRANSFORM");
  igtl::TransformMessage::Pointer transform = igtl::TransformMessage::New();
  transform->SetMessageHeader(header);
  transform->AllocatePack();
  ASSERT_EQ(client->Receive(transform->GetPackBodyPointer(), transform->GetPackBodySize()),
            transform->GetPackBodySize());
  ASSERT_TRUE(transform->Unpack(1) & igtl::MessageHeader::UNPACK_BODY);
  igtl::Matrix4x4 m;
  transform->GetMatrix(m);
  EXPECT_NEAR(m[1][3], -1500.0, 1e-3);

  // Client → server: a TRANSFORM arrives as a pose in metres.
  ToMatrix(X, m);
  const std::vector<uint8_t> sent = LibraryTransform("SlicerTarget", m);
  ASSERT_EQ(client->Send(sent.data(), static_cast<int>(sent.size())), 1);
  ASSERT_TRUE(PollUntil(server, &poses, &events, [&] { return poses.size() == 1; }));
  EXPECT_EQ(poses[0].device, "SlicerTarget");
  EXPECT_TRUE(poses[0].X_m.isApprox(X, 1e-6));

  // A second client is over the limit of one: refused at once.
  igtl::ClientSocket::Pointer second = igtl::ClientSocket::New();
  ASSERT_EQ(second->ConnectToServer("127.0.0.1", server.port()), 0);
  ASSERT_TRUE(PollUntil(server, &poses, &events, [&] {
    for (const IgtlEvent& e : events)
      if (e.kind == IgtlEvent::kRefused && e.detail.find("1 clients already") != std::string::npos)
        return true;
    return false;
  }));
  EXPECT_EQ(server.num_clients(), 1u);
  // The first leaves.
  client->CloseSocket();
  ASSERT_TRUE(PollUntil(server, &poses, &events, [&] { return server.num_clients() == 0; }));
  EXPECT_EQ(events.back().kind, IgtlEvent::kDisconnected);
}

TEST(IgtlServer, RefusesABadAddressByName) {
  IgtlServerOptions options;
  options.bind_address = "localhost:x";
  try {
    IgtlServer server(options);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("localhost:x"), std::string::npos) << e.what();
  }
}

TEST(IgtlBridgeFrames, TheFlangeAtTheDataSheetHeight) {
  const sim::RobotModel model =
      sim::RobotModel::LoadFile(SourceTreePath(sim::RobotModel::kDefaultUrdfRelativePath));
  Eigen::Isometry3d X_WR = Eigen::Isometry3d::Identity();
  X_WR.translation() = Eigen::Vector3d(1, 2, 0.5);
  const auto frames = RobotFrames(model, X_WR, Eigen::VectorXd::Zero(model.num_joints()));
  ASSERT_EQ(frames.size(), static_cast<size_t>(model.num_links()) + 1);
  EXPECT_EQ(frames[0].first, "RobotBase");
  EXPECT_TRUE(frames[0].second.isApprox(X_WR));
  bool found = false;
  for (const auto& [name, X] : frames) {
    EXPECT_LE(name.size(), 20u);
    if (name != "iiwa_link_ee") continue;
    found = true;
    // 0.34 + 0.4 + 0.4 + 0.126 m (KUKA LBR iiwa 7 R800 data sheet) above the base.
    EXPECT_TRUE(X.translation().isApprox(Eigen::Vector3d(1, 2, 0.5 + 1.266), 1e-12)) << X.translation();
  }
  EXPECT_TRUE(found);
}

}  // namespace
}  // namespace orbed::igtl_bridge
