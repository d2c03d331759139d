#include "procs/logger/logger.h"

#include <lcm/lcm.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <optional>
#include <stdexcept>

#include "base/format.h"
#include "base/log.h"
#include "base/sha256.h"
#include "lcmtypes/contract/conversions.h"
#include "procs/logger/event_log_reader.h"

namespace orbed::logger {
namespace {

namespace fs = std::filesystem;

constexpr char kLcmSelfTestChannel[] = "LCM_SELF_TEST";

std::string ChooseLogPath(const LoggerOptions& options, int64_t start_utime) {
  if (!options.file.empty()) return options.file;
  const std::string stem = "orbed-" + FormatUtc(start_utime, "%Y%m%dT%H%M%SZ");
  fs::path path = fs::path(options.log_dir) / (stem + ".lcmlog");
  for (int i = 1; fs::exists(path); ++i) {
    path = fs::path(options.log_dir) / (stem + "-" + std::to_string(i) + ".lcmlog");
  }
  return path.string();
}

// The folder of the log's parts.
fs::path LogFolder(const LoggerOptions& options) {
  return options.file.empty() ? fs::path(options.log_dir) : fs::path(options.file).parent_path();
}

// What is really in a part whose logger died: its whole events, per channel, and the bytes that
// are not a whole event (a torn tail). Throws when the file cannot be read.
void Recount(const fs::path& path, ManifestPart* part) {
  const MappedLog log(path.string());
  if (!log.ok()) throw std::runtime_error(log.error());
  EventLogScanner scanner = log.Scanner();
  ManifestPart recounted;
  recounted.file = part->file;
  recounted.start_utime = part->start_utime;
  recounted.drops = part->drops;
  LogEvent event;
  while (scanner.Next(&event)) {
    ++recounted.events;
    recounted.bytes += static_cast<int64_t>(EventLogWriter::kHeaderBytes + event.channel.size() + event.size);
    ChannelStats one{1, static_cast<int64_t>(event.size), event.timestamp_us, event.timestamp_us};
    Accumulate(one, &recounted.channels[event.channel]);
    recounted.stop_utime = std::max(recounted.stop_utime.value_or(part->start_utime), event.timestamp_us);
  }
  recounted.damaged_bytes = static_cast<int64_t>(scanner.damaged_bytes());
  if (!recounted.stop_utime) recounted.stop_utime = part->start_utime;
  *part = recounted;
}

// The unfinished recording at `manifest_path` that this logger continues, if any.
std::optional<Manifest> RecordingToContinue(const std::string& manifest_path, const LoggerOptions& options) {
  std::error_code ec;
  if (!fs::exists(manifest_path, ec)) return std::nullopt;
  Manifest previous;
  try {
    previous = ReadManifestFile(manifest_path);
  } catch (const JsonReadError& e) {
    throw std::runtime_error(std::string("cannot continue the recording: ") + e.what() +
                             " (move the manifest away to start a new recording)");
  }
  if (previous.complete) return std::nullopt;
  if (!options.file.empty() && previous.parts.front().file != fs::path(options.file).filename().string()) {
    return std::nullopt;
  }
  return previous;
}

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

  const fs::path folder = LogFolder(options_);
  if (std::optional<Manifest> previous = RecordingToContinue(manifest_path(), options_)) {
    manifest_ = *previous;
    ManifestPart& last = manifest_.parts.back();
    try {
      Recount(folder / last.file, &last);
    } catch (const std::runtime_error& e) {
      throw std::runtime_error(std::string("cannot continue the recording: ") + e.what());
    }
    int number = static_cast<int>(manifest_.parts.size()) + 1;
    while (fs::exists(folder / PartFileName(manifest_.parts.front().file, number))) ++number;
    log_path_ = (folder / PartFileName(manifest_.parts.front().file, number)).string();
    ORBED_LOG(kWarn) << "continuing the unfinished recording " << manifest_.parts.front().file << " in part "
                     << number << ": its part " << last.file << " holds " << last.events << " events"
                     << (last.damaged_bytes > 0
                             ? " and " + std::to_string(last.damaged_bytes) + " damaged bytes"
                             : "");
  } else {
    log_path_ = ChooseLogPath(options_, start_utime_);
    manifest_.start_utime = start_utime_;
  }
  const fs::path parent = fs::path(log_path_).parent_path();
  std::error_code ec;
  if (!parent.empty()) fs::create_directories(parent, ec);
  if (ec) throw std::runtime_error("cannot create " + parent.string() + ": " + ec.message());
  file_ = std::make_unique<EventLogWriter>(log_path_);
  if (!file_->ok()) throw std::runtime_error(file_->error());
  ManifestPart part;
  part.file = fs::path(log_path_).filename().string();
  part.start_utime = start_utime_;
  manifest_.parts.push_back(part);
  manifest_.command_line = options_.command_line;
  manifest_.orbed_version = ORBED_VERSION;
  manifest_.lcm_version = std::to_string(LCM_MAJOR_VERSION) + "." + std::to_string(LCM_MINOR_VERSION) + "." +
                          std::to_string(LCM_MICRO_VERSION);
  manifest_.lcm_url = flags_.lcm_url;
  manifest_.channels_regex = options_.channels;
  // The files do not change while we record: hash them once.
  manifest_.files.clear();
  for (const std::string& path : options_.hash_files) {
    std::string error;
    const std::string hash = Sha256FileHex(path, &error);
    manifest_.files.push_back({path, hash, hash.empty() ? error : ""});
  }
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

std::string Logger::manifest_path() const {
  if (!options_.manifest.empty()) return options_.manifest;
  return (LogFolder(options_) / "manifest.json").string();
}

void Logger::OnMessage(const lcm::ReceiveBuffer& rbuf, const std::string& channel) {
  // LCM's own start-up probe (each new LCM instance sends one): not testbed traffic, and no type
  // decodes it, so a replay in lcm-spy would show it as undecodable.
  if (channel == kLcmSelfTestChannel) return;
  const int64_t size = static_cast<int64_t>(rbuf.data_size);
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    if (static_cast<int64_t>(queue_.size()) >= options_.queue_capacity_events ||
        queue_bytes_ + size > options_.queue_capacity_bytes) {
      ++drops_;
      if (drops_ == 1 || drops_ % 1000 == 0) {
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
      ++lost_events_;
      continue;
    }
    std::lock_guard<std::mutex> lock(stats_mutex_);
    ++events_written_;
    bytes_written_ += static_cast<int64_t>(written);
    ChannelStats& stats = stats_[event.channel];
    if (stats.events == 0) stats.first_utime = event.utime;
    ++stats.events;
    stats.bytes += static_cast<int64_t>(event.data.size());
    stats.last_utime = event.utime;
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
    handed_to_writer = events_written_;
  }
  // What the file really holds, whatever was handed to the writer before the failure.
  Manifest manifest = MakeManifest(false);
  ManifestPart& part = manifest.parts.back();
  std::string line;
  try {
    Recount(log_path_, &part);
    const int64_t size = part.bytes + part.damaged_bytes;  // the file's size: every byte is one or the other
    line = error + (in_log ? " after " : "; the log " + log_path_ + " holds ") + std::to_string(size) +
           " bytes, " + std::to_string(part.events) + " events";
  } catch (const std::exception& e) {
    line = error + "; the log cannot be read back: " + e.what();
  }
  part.drops += handed_to_writer - part.events;  // buffered when the write failed: not in the file
  part.error = line;
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
  {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    status.events_written = events_written_;
    status.bytes_written = bytes_written_;
    status.last_flush_utime = last_flush_utime_;
  }
  int64_t lost = 0;
  {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    lost = lost_events_;
  }
  std::lock_guard<std::mutex> lock(queue_mutex_);
  status.drops = drops_ + lost;
  status.queue_depth = static_cast<int32_t>(queue_.size());
  status.queue_capacity = static_cast<int32_t>(options_.queue_capacity_events);
  return status;
}

std::map<std::string, ChannelStats> Logger::channel_stats() const {
  std::lock_guard<std::mutex> lock(stats_mutex_);
  return stats_;
}

Manifest Logger::MakeManifest(bool complete) const {
  Manifest m = manifest_;
  ManifestPart& part = m.parts.back();
  const orbed::logger_status_t status = MakeStatus();
  part.drops = status.drops;
  {
    std::lock_guard<std::mutex> lock(stats_mutex_);
    part.events = events_written_;
    part.bytes = bytes_written_;
    part.channels = stats_;
  }
  if (complete) {
    m.complete = part.complete = true;
    m.stop_utime = part.stop_utime = stop_utime_;
  }
  return m;
}

bool Logger::WriteManifest(bool complete, std::string* error) const {
  return WriteManifestFile(manifest_path(), MakeManifest(complete), error);
}

}  // namespace orbed::logger
