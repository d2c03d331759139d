#include "procs/logger/logger.h"

#include <lcm/lcm.h>

#include <chrono>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "base/json.h"
#include "base/sha256.h"
#include "procs/common/conversions.h"
#include "procs/common/log.h"

namespace orbed::logger {
namespace {

namespace fs = std::filesystem;

constexpr char kLcmSelfTestChannel[] = "LCM_SELF_TEST";

std::string UtcStamp(int64_t utime, const char* format) {
  const std::time_t seconds = static_cast<std::time_t>(utime / 1000000);
  std::tm tm{};
  gmtime_r(&seconds, &tm);
  char buffer[64];
  std::strftime(buffer, sizeof(buffer), format, &tm);
  return buffer;
}

std::string ChooseLogPath(const LoggerOptions& options, int64_t start_utime) {
  if (!options.file.empty()) return options.file;
  const std::string stem = "orbed-" + UtcStamp(start_utime, "%Y%m%dT%H%M%SZ");
  fs::path path = fs::path(options.log_dir) / (stem + ".lcmlog");
  for (int i = 1; fs::exists(path); ++i) {
    path = fs::path(options.log_dir) / (stem + "-" + std::to_string(i) + ".lcmlog");
  }
  return path.string();
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

  log_path_ = ChooseLogPath(options_, start_utime_);
  const fs::path parent = fs::path(log_path_).parent_path();
  std::error_code ec;
  if (!parent.empty()) fs::create_directories(parent, ec);
  if (ec) throw std::runtime_error("cannot create " + parent.string() + ": " + ec.message());
  file_ = std::make_unique<EventLogWriter>(log_path_);
  if (!file_->ok()) throw std::runtime_error(file_->error());
  // The files do not change while we record: hash them once.
  for (const std::string& path : options_.hash_files) {
    std::string error;
    const std::string hash = Sha256FileHex(path, &error);
    file_hashes_.push_back({path, hash, hash.empty() ? error : ""});
  }
  process_.AddTimer(1.0, [this] { process_.Publish(options_.status_channel, MakeStatus()); });
  process_.AddTimer(5.0, [this] { WriteManifest(false); });
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
  return (fs::path(log_path_).parent_path() / "manifest.json").string();
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
    for (const Event& event : batch) {
      const size_t written = file_->Write(event.utime, event.channel, event.data.data(), event.data.size());
      std::lock_guard<std::mutex> lock(stats_mutex_);
      if (written == 0) {
        // Disk full or gone: every later event is lost too. Say so once, count the losses as
        // drops, and stop the logger (its exit code and heartbeat say FAILED).
        if (write_error_.empty()) {
          write_error_ = file_->error();
          process_.Fail("log write failed: " + write_error_);
        }
        ++lost_events_;
        continue;
      }
      ++events_written_;
      bytes_written_ += static_cast<int64_t>(written);
      ChannelStats& stats = stats_[event.channel];
      if (stats.events == 0) stats.first_utime = event.utime;
      ++stats.events;
      stats.bytes += static_cast<int64_t>(event.data.size());
      stats.last_utime = event.utime;
    }
    batch.clear();
    if (stop || Clock::now() >= next_flush) {
      const bool flushed = file_->Flush();
      std::lock_guard<std::mutex> lock(stats_mutex_);
      if (!flushed && write_error_.empty()) {
        write_error_ = file_->error();
        process_.Fail("log flush failed: " + write_error_);
      }
      last_flush_utime_ = NowMicros();
      next_flush = Clock::now() + flush_period;
    }
    if (stop) break;
  }
  file_->Close();
}

int Logger::Run() {
  ORBED_LOG(kInfo) << "recording channels /" << options_.channels << "/ to " << log_path_;
  WriteManifest(false);
  writer_ = std::thread([this] { WriterLoop(); });
  const int code = process_.Run();
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    writer_stop_ = true;
  }
  queue_cv_.notify_all();
  writer_.join();
  stop_utime_ = NowMicros();
  WriteManifest(true);
  const orbed::logger_status_t status = MakeStatus();
  ORBED_LOG(kInfo) << "closed " << log_path_ << ": " << status.events_written << " events, "
                   << status.bytes_written << " bytes, " << status.drops << " dropped";
  std::lock_guard<std::mutex> lock(stats_mutex_);
  if (!write_error_.empty()) {
    ORBED_LOG(kError) << write_error_;
    return 1;
  }
  return code;
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

void Logger::WriteManifest(bool complete) const {
  const orbed::logger_status_t status = MakeStatus();
  JsonWriter json(2);
  json.BeginObject();
  json.Key("log_file").String(fs::path(log_path_).filename().string());
  json.Key("complete").Bool(complete);
  json.Key("start_utime").Int(start_utime_);
  json.Key("start_time_utc").String(UtcStamp(start_utime_, "%Y-%m-%dT%H:%M:%SZ"));
  if (complete) {
    json.Key("stop_utime").Int(stop_utime_);
    json.Key("stop_time_utc").String(UtcStamp(stop_utime_, "%Y-%m-%dT%H:%M:%SZ"));
  }
  json.Key("command_line").String(options_.command_line);
  json.Key("versions").BeginObject();
  json.Key("orbed").String(ORBED_VERSION);
  json.Key("lcm").String(std::to_string(LCM_MAJOR_VERSION) + "." + std::to_string(LCM_MINOR_VERSION) + "." +
                         std::to_string(LCM_MICRO_VERSION));
  json.EndObject();
  json.Key("lcm_url").String(flags_.lcm_url);
  json.Key("channels_regex").String(options_.channels);
  json.Key("files").BeginArray();
  for (const FileHash& file : file_hashes_) {
    json.BeginObject();
    json.Key("path").String(file.path);
    if (file.sha256.empty()) {
      json.Key("error").String(file.error);
    } else {
      json.Key("sha256").String(file.sha256);
    }
    json.EndObject();
  }
  json.EndArray();
  json.Key("events_written").Int(status.events_written);
  json.Key("bytes_written").Int(status.bytes_written);
  json.Key("drops").Int(status.drops);
  json.Key("channels").BeginObject();
  for (const auto& [channel, stats] : channel_stats()) {
    json.Key(channel).BeginObject();
    json.Key("events").Int(stats.events);
    json.Key("bytes").Int(stats.bytes);
    json.Key("first_utime").Int(stats.first_utime);
    json.Key("last_utime").Int(stats.last_utime);
    json.EndObject();
  }
  json.EndObject();
  json.EndObject();
  // Write-then-rename so a reader never sees half a manifest.
  const std::string path = manifest_path();
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp);
    out << json.str() << "\n";
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) ORBED_LOG(kWarn) << "cannot write " << path << ": " << ec.message();
}

}  // namespace orbed::logger
