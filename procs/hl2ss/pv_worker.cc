#include "procs/hl2ss/pv_worker.h"

#include <algorithm>
#include <exception>
#include <utility>

namespace orbed::hl2ss {

void PvHandBack::Push(PvResult result) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    queue_.push_back(std::move(result));
  }
  if (on_push_) on_push_();
}

std::vector<PvResult> PvHandBack::TakeAll() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<PvResult> out;
  out.swap(queue_);
  return out;
}

void PvHandBack::Discard(int client) {
  std::lock_guard<std::mutex> lock(mutex_);
  queue_.erase(std::remove_if(queue_.begin(), queue_.end(),
                              [client](const PvResult& r) { return r.client == client; }),
               queue_.end());
}

PvEncoderWorker::PvEncoderWorker(int client, PvEncodeFn encode, PvHandBack* out)
    : client_(client), encode_(std::move(encode)), out_(out), thread_([this] { Loop(); }) {}

PvEncoderWorker::~PvEncoderWorker() {
  RequestStop();
  thread_.join();
}

void PvEncoderWorker::RequestStop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
    mailbox_.reset();
  }
  wake_.notify_one();
}

bool PvEncoderWorker::Offer(PvJob job) {
  bool replaced = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (stop_) return true;  // stopping: nothing is encoded any more, and nothing was waiting
    replaced = mailbox_.has_value();
    mailbox_ = std::move(job);
  }
  wake_.notify_one();
  return !replaced;
}

void PvEncoderWorker::RequestKeyFrame() {
  std::lock_guard<std::mutex> lock(mutex_);
  key_frame_next_ = true;
}

void PvEncoderWorker::Loop() {
  for (;;) {
    PvJob job;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [this] { return stop_ || mailbox_.has_value(); });
      if (stop_) return;
      job = std::move(*mailbox_);
      mailbox_.reset();
      job.key_frame = job.key_frame || key_frame_next_;
      key_frame_next_ = false;
    }
    PvResult result;
    result.client = client_;
    result.timestamp = job.timestamp;
    result.pose = job.pose;
    result.key_frame = job.key_frame;
    try {
      if (!encode_(job, &result.payload, &result.error)) {
        result.payload.clear();
        if (result.error.empty()) result.error = "the encoder failed";
      }
    } catch (const std::exception& e) {
      result.payload.clear();
      result.error = e.what();
    }
    out_->Push(std::move(result));
  }
}

}  // namespace orbed::hl2ss
