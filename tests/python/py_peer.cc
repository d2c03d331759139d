// orbed-py-peer: the C++ side of the Python package's tests (python/tests), on LCM's own C++ library.
//   orbed-py-peer fingerprints       every message type as "<type> <fingerprint, 16 hex digits>"
//   orbed-py-peer echo IN OUT        waits (up to 60 s) for one image_t on IN, decoded through
//                                    DecodeBounded, prints "<num_bytes> <SHA-256 of data>" and
//                                    publishes the decoded message again on OUT; exit 0, or 1 on
//                                    timeout or a refused message
// The bus is $ORBED_LCM_URL, else udpm://239.255.76.67:7667?ttl=0 with an 8 MB receive buffer.
#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <string>

#include <lcm/lcm-cpp.hpp>
#include <orbed/all_types.hpp>

#include "base/sha256.h"
#include "lcmtypes/bounded_decode.h"

namespace {

int PrintFingerprints() {
#define ORBED_PRINT_FINGERPRINT(T) \
  std::printf("%s %016" PRIx64 "\n", #T, static_cast<uint64_t>(orbed::T::getHash()));
  ORBED_FOR_EACH_LCM_TYPE(ORBED_PRINT_FINGERPRINT)
#undef ORBED_PRINT_FINGERPRINT
  return 0;
}

class Echo {
 public:
  explicit Echo(std::string out) : out_(std::move(out)) {}
  void OnImage(const lcm::ReceiveBuffer* rbuf, const std::string&) {
    if (done_) return;
    done_ = true;
    orbed::image_t image;
    const orbed::DecodeResult decoded = orbed::DecodeBounded(rbuf->data, rbuf->data_size, &image);
    if (!decoded.ok()) {
      std::printf("refused %s\n", decoded.error.c_str());
      return;
    }
    ok_ = true;
    const std::string bytes(image.data.begin(), image.data.end());
    std::printf("%d %s\n", image.num_bytes, orbed::Sha256Hex(bytes).c_str());
    std::fflush(stdout);
    lcm_->publish(out_, &image);
  }
  lcm::LCM* lcm_ = nullptr;
  bool done_ = false, ok_ = false;

 private:
  std::string out_;
};

int RunEcho(const std::string& in, const std::string& out) {
  const char* env = std::getenv("ORBED_LCM_URL");
  lcm::LCM lcm(env != nullptr && env[0] != '\0' ? env
                                                : "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=8388608");
  if (!lcm.good()) return 1;
  Echo echo(out);
  echo.lcm_ = &lcm;
  lcm.subscribe(in, &Echo::OnImage, &echo);
  std::printf("subscribed\n");
  std::fflush(stdout);
  for (int waited_ms = 0; !echo.done_ && waited_ms < 60000; waited_ms += 100) lcm.handleTimeout(100);
  return echo.ok_ ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string mode = argc > 1 ? argv[1] : "";
  if (mode == "fingerprints" && argc == 2) return PrintFingerprints();
  if (mode == "echo" && argc == 4) return RunEcho(argv[2], argv[3]);
  std::fprintf(stderr, "usage: orbed-py-peer fingerprints | echo IN OUT\n");
  return 2;
}
