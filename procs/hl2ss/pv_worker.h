#pragma once
/// @file
/// Front-camera (PV) encoding off the process thread: one PvEncoderWorker per PV client, each a
/// thread with a one-slot mailbox, and a PvHandBack queue through which every worker returns its
/// finished payloads to the process thread (the only thread that may touch the sockets).
///
/// Why: H.265 at 1920×1080 takes 40–55 ms a picture on the development machine (docs/hl2ss.md),
/// longer than a camera period; encoding on the process thread would stall spatial input (30 Hz)
/// and every socket. A worker instead encodes the newest picture it has been offered:
///   - Offer() puts a job in the mailbox; a job still waiting there is replaced (latest wins) and
///     Offer() says so, for the caller to count the drop;
///   - the worker takes the job, runs the encode function on it (outside any lock) and pushes the
///     result, tagged with the client, into the PvHandBack;
///   - the process thread drains the PvHandBack (TakeAll) in its poll and sends;
///   - RequestKeyFrame() marks the next job the worker takes (the one waiting, or the next offered)
///     `key_frame`, for the encode function to make an IDR of; a request is consumed only by a
///     job taken, so a replaced job does not lose it.
/// Stopping (RequestStop, then the destructor): the waiting job is discarded, the thread is told to
/// stop and joined; it returns after the encode in progress, so the caller blocks at most one
/// picture's encode.
/// Results the worker pushed before it stopped stay in the PvHandBack: the caller removes them
/// with Discard(client) after the join.
///
/// No sleeps: a condition variable wakes the worker. The encode function is injected (the
/// production one calls PvEncoder::Encode; tests control when a fake one returns).
///
/// Threading: PvHandBack is thread-safe. A PvEncoderWorker's methods are called from one thread
/// (the process thread); its encode function runs on the worker's own thread, one call at a time.

#include <array>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <opencv2/core.hpp>

#include "geometry/camera_model.h"
#include "procs/hl2ss/pv_encoder.h"

namespace orbed::hl2ss {

/// One picture to encode for one client.
struct PvJob {
  cv::Mat bgr;                                ///< shared, read-only: the camera picture at its own size
  geometry::Intrinsics K;                     ///< of `bgr`
  PvCaptureMetadata metadata;                 ///< the trailer's capture fields
  std::uint64_t timestamp{0};                 ///< hl2ss ticks, for the packet
  std::optional<std::array<float, 16>> pose;  ///< the mode-1 pose (frames.h), nullopt in mode 0
  bool key_frame{false};                      ///< encode as a key frame (set by RequestKeyFrame)
};

/// What a worker hands back: the packet's parts, or why the encode failed.
struct PvResult {
  int client{-1};
  std::uint64_t timestamp{0};
  std::vector<std::uint8_t> payload;
  std::optional<std::array<float, 16>> pose;
  bool key_frame{false};  ///< the job asked for a key frame
  std::string error;      ///< non-empty: no payload
};

/// Encodes one job into *payload; false and *error on failure. Runs on a worker thread.
using PvEncodeFn =
    std::function<bool(const PvJob& job, std::vector<std::uint8_t>* payload, std::string* error)>;

/// The thread-safe queue of finished payloads, drained by the process thread.
class PvHandBack {
 public:
  void Push(PvResult result);
  /// Everything handed back so far, oldest first.
  std::vector<PvResult> TakeAll();
  /// Drops what is queued for `client` (after its worker was joined).
  void Discard(int client);
  /// Called (on the worker thread, outside the lock) after each Push: e.g. to wake a poller. Set
  /// before any worker starts.
  void set_on_push(std::function<void()> on_push) { on_push_ = std::move(on_push); }

 private:
  std::mutex mutex_;
  std::vector<PvResult> queue_;
  std::function<void()> on_push_;
};

class PvEncoderWorker {
 public:
  /// Starts the thread. `out` must outlive the worker.
  PvEncoderWorker(int client, PvEncodeFn encode, PvHandBack* out);
  /// RequestStop(), then joins the thread (after the encode in progress).
  ~PvEncoderWorker();
  PvEncoderWorker(const PvEncoderWorker&) = delete;
  PvEncoderWorker& operator=(const PvEncoderWorker&) = delete;

  /// Puts `job` in the mailbox. Returns false when it replaced a job still waiting there (that
  /// one is dropped: count it).
  bool Offer(PvJob job);

  /// Discards a waiting job and tells the thread to stop after the encode in progress, without
  /// waiting for it. Later offers are discarded.
  void RequestStop();

  /// The next job taken is marked key_frame (see the file comment).
  void RequestKeyFrame();

  int client() const { return client_; }

 private:
  void Loop();

  const int client_;
  PvEncodeFn encode_;
  PvHandBack* out_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::optional<PvJob> mailbox_;
  bool stop_{false};
  bool key_frame_next_{false};
  std::thread thread_;  // last: started after the members it uses
};

}  // namespace orbed::hl2ss
