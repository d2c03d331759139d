// The PV encoder worker with a fake encoder the test holds: each encode blocks until the test
// releases it, so which picture is encoded, which is dropped and when the worker stops are decided
// by the test, not by timing. Waits are on condition variables with generous timeouts.
#include "procs/hl2ss/pv_worker.h"

#include <chrono>
#include <condition_variable>
#include <future>
#include <mutex>
#include <stdexcept>

#include <gtest/gtest.h>

namespace orbed::hl2ss {
namespace {

constexpr auto kTimeout = std::chrono::seconds(30);

// An encoder that records each job's stamp, then waits for the test's Release().
class HeldEncoder {
 public:
  PvEncodeFn Fn() {
    return [this](const PvJob& job, std::vector<std::uint8_t>* payload, std::string* error) {
      std::unique_lock<std::mutex> lock(mutex_);
      started_.push_back(job.timestamp);
      key_frames_.push_back(job.key_frame);
      changed_.notify_all();
      const size_t me = started_.size();
      changed_.wait(lock, [&] { return released_ >= me; });
      if (job.timestamp == kFail) {
        *error = "cannot";
        return false;
      }
      if (job.timestamp == kThrow) throw std::runtime_error("thrown");
      payload->assign(1, static_cast<std::uint8_t>(job.timestamp));
      return true;
    };
  }
  // Waits until `n` encodes have started; false on timeout.
  bool WaitStarted(size_t n) {
    std::unique_lock<std::mutex> lock(mutex_);
    return changed_.wait_for(lock, kTimeout, [&] { return started_.size() >= n; });
  }
  void Release() {
    std::lock_guard<std::mutex> lock(mutex_);
    ++released_;
    changed_.notify_all();
  }
  std::vector<std::uint64_t> started() {
    std::lock_guard<std::mutex> lock(mutex_);
    return started_;
  }
  std::vector<bool> key_frames() {
    std::lock_guard<std::mutex> lock(mutex_);
    return key_frames_;
  }
  static constexpr std::uint64_t kFail = 200, kThrow = 201;

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<std::uint64_t> started_;
  std::vector<bool> key_frames_;
  size_t released_{0};
};

// A hand-back the test can wait on.
class WatchedHandBack {
 public:
  WatchedHandBack() {
    queue.set_on_push([this] {
      std::lock_guard<std::mutex> lock(mutex_);
      ++pushes_;
      pushed_.notify_all();
    });
  }
  bool WaitPushes(int n) {
    std::unique_lock<std::mutex> lock(mutex_);
    return pushed_.wait_for(lock, kTimeout, [&] { return pushes_ >= n; });
  }
  PvHandBack queue;

 private:
  std::mutex mutex_;
  std::condition_variable pushed_;
  int pushes_{0};
};

PvJob Job(std::uint64_t stamp) {
  PvJob j;
  j.timestamp = stamp;
  j.pose = std::array<float, 16>{};
  (*j.pose)[15] = static_cast<float>(stamp);
  return j;
}

TEST(PvWorker, EncodesTheLatestPictureAndCountsTheReplacedOne) {
  HeldEncoder encoder;
  WatchedHandBack back;
  PvEncoderWorker worker(7, encoder.Fn(), &back.queue);
  EXPECT_TRUE(worker.Offer(Job(1)));
  ASSERT_TRUE(encoder.WaitStarted(1));  // 1 is being encoded: the mailbox is empty again
  EXPECT_TRUE(worker.Offer(Job(2)));
  EXPECT_FALSE(worker.Offer(Job(3))) << "2 was waiting: replaced, a drop";
  EXPECT_FALSE(worker.Offer(Job(4))) << "3 was waiting: replaced, a drop";
  encoder.Release();
  ASSERT_TRUE(encoder.WaitStarted(2));
  encoder.Release();
  ASSERT_TRUE(back.WaitPushes(2));
  EXPECT_EQ(encoder.started(), (std::vector<std::uint64_t>{1, 4}));
  const std::vector<PvResult> results = back.queue.TakeAll();
  ASSERT_EQ(results.size(), 2u);
  EXPECT_EQ(results[0].client, 7);
  EXPECT_EQ(results[0].timestamp, 1u);
  EXPECT_EQ(results[0].payload, std::vector<std::uint8_t>{1});
  ASSERT_TRUE(results[0].pose);
  EXPECT_EQ((*results[0].pose)[15], 1.0f) << "the job's pose comes back with its payload";
  EXPECT_EQ(results[1].timestamp, 4u);
  EXPECT_TRUE(results[1].error.empty());
  EXPECT_TRUE(back.queue.TakeAll().empty()) << "taken once";
}

TEST(PvWorker, AKeyFrameRequestGoesToTheNextJobTakenEvenWhenTheWaitingOneIsReplaced) {
  HeldEncoder encoder;
  WatchedHandBack back;
  PvEncoderWorker worker(3, encoder.Fn(), &back.queue);
  EXPECT_TRUE(worker.Offer(Job(1)));
  ASSERT_TRUE(encoder.WaitStarted(1));
  worker.RequestKeyFrame();  // while 1 is being encoded: for the next job taken
  EXPECT_TRUE(worker.Offer(Job(2)));
  EXPECT_FALSE(worker.Offer(Job(3))) << "2 replaced: the request stays";
  encoder.Release();
  ASSERT_TRUE(encoder.WaitStarted(2));
  encoder.Release();
  ASSERT_TRUE(back.WaitPushes(2));
  EXPECT_TRUE(worker.Offer(Job(4)));  // the request was consumed by 3
  ASSERT_TRUE(encoder.WaitStarted(3));
  encoder.Release();
  ASSERT_TRUE(back.WaitPushes(3));
  EXPECT_EQ(encoder.started(), (std::vector<std::uint64_t>{1, 3, 4}));
  EXPECT_EQ(encoder.key_frames(), (std::vector<bool>{false, true, false}));
  const std::vector<PvResult> results = back.queue.TakeAll();
  ASSERT_EQ(results.size(), 3u);
  EXPECT_FALSE(results[0].key_frame);
  EXPECT_TRUE(results[1].key_frame) << "the result says so, for the sender";
  EXPECT_FALSE(results[2].key_frame);
}

TEST(PvWorker, StoppingWaitsForTheEncodeInProgressOnlyAndDropsTheWaitingPicture) {
  HeldEncoder encoder;
  WatchedHandBack back;
  auto worker = std::make_unique<PvEncoderWorker>(3, encoder.Fn(), &back.queue);
  worker->Offer(Job(1));
  ASSERT_TRUE(encoder.WaitStarted(1));
  worker->Offer(Job(2));  // waiting when the client leaves
  worker->RequestStop();  // what the destructor does first, here before 1 is released
  EXPECT_TRUE(worker->Offer(Job(3))) << "discarded, not counted as replacing anything";
  std::promise<void> stopped;
  std::future<void> done = stopped.get_future();
  std::thread stopper([&] {
    worker.reset();  // the process thread's part: blocks until the encode of 1 returns
    stopped.set_value();
  });
  encoder.Release();
  ASSERT_EQ(done.wait_for(kTimeout), std::future_status::ready);
  stopper.join();
  EXPECT_EQ(encoder.started(), std::vector<std::uint64_t>{1}) << "2 and 3 were never encoded";
  // What the worker handed back before it stopped is discarded by the caller.
  ASSERT_TRUE(back.WaitPushes(1));
  back.queue.Discard(3);
  EXPECT_TRUE(back.queue.TakeAll().empty());
}

TEST(PvWorker, AnIdleWorkerStopsAtOnceAndDiscardKeepsOtherClients) {
  HeldEncoder encoder;
  WatchedHandBack back;
  { PvEncoderWorker idle(1, encoder.Fn(), &back.queue); }  // joined without ever encoding
  EXPECT_TRUE(encoder.started().empty());
  back.queue.Push(PvResult{1, 10, {}, std::nullopt, false, ""});
  back.queue.Push(PvResult{2, 11, {}, std::nullopt, false, ""});
  back.queue.Discard(1);
  const std::vector<PvResult> left = back.queue.TakeAll();
  ASSERT_EQ(left.size(), 1u);
  EXPECT_EQ(left[0].client, 2);
}

TEST(PvWorker, FailuresComeBackAsErrors) {
  HeldEncoder encoder;
  WatchedHandBack back;
  PvEncoderWorker worker(5, encoder.Fn(), &back.queue);
  worker.Offer(Job(HeldEncoder::kFail));
  ASSERT_TRUE(encoder.WaitStarted(1));
  encoder.Release();
  ASSERT_TRUE(back.WaitPushes(1));
  worker.Offer(Job(HeldEncoder::kThrow));
  ASSERT_TRUE(encoder.WaitStarted(2));
  encoder.Release();
  ASSERT_TRUE(back.WaitPushes(2));
  const std::vector<PvResult> results = back.queue.TakeAll();
  ASSERT_EQ(results.size(), 2u);
  EXPECT_EQ(results[0].error, "cannot");
  EXPECT_TRUE(results[0].payload.empty());
  EXPECT_EQ(results[1].error, "thrown");
}

}  // namespace
}  // namespace orbed::hl2ss
