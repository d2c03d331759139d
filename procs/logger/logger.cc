#include "procs/logger/logger.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <stdexcept>

#include "base/log.h"
#include "lcmtypes/contract/conversions.h"

namespace orbed::logger {
namespace {

constexpr char kLcmSelfTestChannel[] = "LCM_SELF_TEST";

}  // namespace

Logger::Logger(const CommonFlags& flags, LoggerOptions options)
    : options_(std::move(options)), flags_(flags), process_(flags), start_utime_(NowMicros()) {
  if (options_.queue_capacity_events <= 0 || options_.queue_capacity_bytes <= 0) {
    throw std::invalid_argument("queue capacities must be > 0");
  }
  if (!(options_.flush_interval_s > 0)) {
    throw std::invalid_argument("flush interval must be > 0 s");
  }
  // Subscribe first: a malformed --channels regex throws before any file is created.
  lcm::Subscription* subscription = process_.SubscribeRaw(
      options_.channels,
      [this](const lcm::ReceiveBuffer& rbuf, const std::string& channel) { OnMessage(rbuf, channel); });
  subscription->setQueueCapacity(options_.lcm_queue_capacity);

  RecordingStart start = StartRecording(options_, flags_.lcm_url, start_utime_);
  if (!start.continuing.empty()) ORBED_LOG(kWarn) << start.continuing;
  manifest_ = std::move(start.manifest);
  log_path_ = std::move(start.log_path);
  const std::filesystem::path parent = std::filesystem::path(log_path_).parent_path();
  std::error_code ec;
  if (!parent.empty()) std::filesystem::create_directories(parent, ec);
  if (ec) throw std::runtime_error("cannot create " + parent.string() + ": " + ec.message());
  file_ = std::make_unique<EventLogWriter>(log_path_);
  if (!file_->ok()) throw std::runtime_error(file_->error());
  process_.AddTimer(1.0, [this] { process_.Publish(options_.status_channel, MakeStatus()); });
  process_.AddTimer(5.0, [this] {
    std::string error;
    if (!WriteManifest(false, &error)) StopOnWriteError(error, false);
  });
}

Logger::~Logger() {
  if (writer_.joinable()) {
    {
      std::lock_guard<std::mutex> lock(queue_mutex_);
      writer_stop_ = true;
    }
    queue_cv_.notify_all();
    writer_.join();
  }
}

std::string Logger::manifest_path() const { return ManifestPath(options_); }

void Logger::OnMessage(const lcm::ReceiveBuffer& rbuf, const std::string& channel) {
  // LCM's own start-up probe (each new LCM instance sends one): not testbed traffic, and no type
  // decodes it, so a replay in lcm-spy would show it as undecodable.
  if (channel == kLcmSelfTestChannel) return;
  const int64_t size = static_cast<int64_t>(rbuf.data_size);
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    if (!QueueFits(options_, static_cast<int64_t>(queue_.size()), queue_bytes_, size)) {
      if (LogDrop(++drops_)) {
        ORBED_LOG(kWarn) << "queue full (" << queue_.size() << " events, " << queue_bytes_
                         << " bytes): dropped " << drops_ << " so far";
      }
      return;
    }
    const auto* bytes = static_cast<const uint8_t*>(rbuf.data);
    queue_.push_back(Event{rbuf.recv_utime, channel, std::vector<uint8_t>(bytes, bytes + size)});
    queue_bytes_ += size;
  }
  queue_cv_.notify_one();
}

void Logger::WriterLoop() {
  using Clock = std::chrono::steady_clock;
  const auto flush_period =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(options_.flush_interval_s));
  auto next_flush = Clock::now() + flush_period;
  std::deque<Event> batch;
  for (;;) {
    bool stop = false;
    {
      std::unique_lock<std::mutex> lock(queue_mutex_);
      queue_cv_.wait_until(lock, next_flush, [this] { return writer_stop_ || !queue_.empty(); });
      batch.swap(queue_);
      queue_bytes_ = 0;
      stop = writer_stop_;
    }
    WriteBatch(batch);
    batch.clear();
    if (stop || Clock::now() >= next_flush) {
      if (file_->Flush()) {
        std::lock_guard<std::mutex> lock(stats_mutex_);
        last_flush_utime_ = NowMicros();
      } else {
        StopOnWriteError(file_->error(), true);
      }
      next_flush = Clock::now() + flush_period;
    }
    if (stop) break;
  }
  if (!file_->Close()) StopOnWriteError(file_->error(), true);
}

void Logger::StopOnWriteError(const std::string& error, bool in_log) {
  {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    if (!write_error_.empty()) return;
    write_error_ = error;
    log_write_failed_ = in_log;
  }
  process_.Fail(error);
}

void Logger::WriteBatch(const std::deque<Event>& batch) {
  for (const Event& event : batch) {
    const size_t written = file_->Write(event.utime, event.channel, event.data.data(), event.data.size());
    if (written == 0) {
      // Disk full or gone: every later event is lost too. Say so once, count the losses as
      // drops, and stop the logger (its exit code and heartbeat say FAILED).
      StopOnWriteError(file_->error(), true);
      std::lock_guard<std::mutex> lock(stats_mutex_);
      ++counts_.lost_events;
      continue;
    }
    std::lock_guard<std::mutex> lock(stats_mutex_);
    counts_.Written(event.channel, event.utime, static_cast<int64_t>(event.data.size()),
                    static_cast<int64_t>(written));
  }
}

void Logger::WriteQueued() {
  std::deque<Event> batch;
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    batch.swap(queue_);
    queue_bytes_ = 0;
  }
  WriteBatch(batch);
}

int Logger::Run() {
  ORBED_LOG(kInfo) << "recording channels /" << options_.channels << "/ to " << log_path_;
  std::string error;
  if (!WriteManifest(false, &error)) StopOnWriteError(error, false);
  writer_ = std::thread([this] { WriterLoop(); });
  const int code = process_.Run();
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    writer_stop_ = true;
  }
  queue_cv_.notify_all();
  writer_.join();  // the log is closed
  stop_utime_ = NowMicros();
  {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    error = write_error_;
  }
  if (error.empty() && !WriteManifest(true, &error)) StopOnWriteError(error, false);
  if (!error.empty()) return EndFailedRecording();
  const orbed::logger_status_t status = MakeStatus();
  ORBED_LOG(kInfo) << "closed " << log_path_ << ": " << status.events_written << " events, "
                   << status.bytes_written << " bytes, " << status.drops << " dropped";
  return code;
}

int Logger::EndFailedRecording() {
  std::string error;
  bool in_log = false;
  int64_t handed_to_writer = 0;
  {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    error = write_error_;
    in_log = log_write_failed_;
    handed_to_writer = counts_.events_written;
  }
  std::string line;
  const Manifest manifest =
      FailedRecording(MakeManifest(false), error, in_log, log_path_, handed_to_writer, &line);
  std::string manifest_error;
  if (WriteManifestFile(manifest_path(), manifest, &manifest_error)) {
    line += "; recorded in " + manifest_path();
  } else {
    line += "; " + manifest_path() + " not updated: " + manifest_error;
  }
  ORBED_LOG(kError) << line;  // the last line: orbed-launch names it as the reason
  return kExitCannotWrite;
}

orbed::logger_status_t Logger::MakeStatus() const {
  orbed::logger_status_t status{};
  status.utime = NowMicros();
  status.file = log_path_;
  int64_t lost = 0;
  {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    status.events_written = counts_.events_written;
    status.bytes_written = counts_.bytes_written;
    status.last_flush_utime = last_flush_utime_;
    lost = counts_.lost_events;
  }
  std::lock_guard<std::mutex> lock(queue_mutex_);
  status.drops = drops_ + lost;
  status.queue_depth = static_cast<int32_t>(queue_.size());
  status.queue_capacity = static_cast<int32_t>(options_.queue_capacity_events);
  return status;
}

std::map<std::string, ChannelStats> Logger::channel_stats() const {
  std::lock_guard<std::mutex> lock(stats_mutex_);
  return counts_.channels;
}

Manifest Logger::MakeManifest(bool complete) const {
  const int64_t drops = MakeStatus().drops;
  std::lock_guard<std::mutex> lock(stats_mutex_);
  return ManifestNow(manifest_, counts_, drops, complete, stop_utime_);
}

bool Logger::WriteManifest(bool complete, std::string* error) const {
  return WriteManifestFile(manifest_path(), MakeManifest(complete), error);
}

}  // namespace orbed::logger
