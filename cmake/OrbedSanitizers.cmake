# The sanitizer build: -DORBED_SANITIZE=address,undefined (`scripts/orbed test` builds it with
# clang into build-asan/ and runs the whole suite there). Every finding fails the test that made it:
#   - every report is fatal (-fno-sanitize-recover=all: UBSan would otherwise print and go on);
#   - ORBED_SANITIZER_ENV, the runtime options, goes into each test's environment and from there into
#     every process the test starts (children inherit it): leak checks on, halt on the first report,
#     LeakSanitizer's suppressions (tests/lsan.supp: leaks inside third-party libraries only);
#   - ORBED_SANITIZER_REPORT, a report's first line, fails a test whose output holds it, whatever the
#     exit code: a child's report reaches the test's output through testbed_util's relay, a
#     launcher child's through orbed-launch's.
# orbed_sanitizer_test_properties() (cmake/OrbedHelpers.cmake) applies both to a test.
if(NOT ORBED_SANITIZE)
  return()
endif()

add_compile_options(-fsanitize=${ORBED_SANITIZE} -fno-sanitize-recover=all -fno-omit-frame-pointer)
add_link_options(-fsanitize=${ORBED_SANITIZE})

# GCC 12's -fsanitize=vptr (part of `undefined`) miscompiles a call through a pointer to member
# function read from a polymorphic object, `(s->handler->*s->method)(...)`: it checks the wrong
# address, reports "does not point to an object of type" and then calls on a null or misaligned
# pointer. LCM's typed subscriptions dispatch exactly so (lcm-cpp-impl.hpp:88, LCMMHSubscription), so
# every test with one fails under GCC while the program is correct (clang is right). Turn vptr off
# only where this check program crashes.
if(ORBED_SANITIZE MATCHES "undefined|vptr")
  include(CheckCXXSourceRuns)
  set(CMAKE_REQUIRED_FLAGS "-fsanitize=vptr -fno-sanitize-recover=all")
  set(CMAKE_REQUIRED_LINK_OPTIONS "-fsanitize=vptr")
  check_cxx_source_runs([[
    struct Handler { int n = 0; void On(int k) { n += k; } };
    struct Base { virtual ~Base() = default; };
    struct Sub : Base { Handler* handler; void (Handler::*method)(int); };
    void Call(void* user_data) {
      Sub* s = static_cast<Sub*>(user_data);
      (s->handler->*s->method)(1);
    }
    int main() {
      Handler h;
      Sub s;
      s.handler = &h;
      s.method = &Handler::On;
      Call(&s);
      return h.n == 1 ? 0 : 1;
    }]] ORBED_VPTR_MEMBER_CALL_WORKS)
  unset(CMAKE_REQUIRED_FLAGS)
  unset(CMAKE_REQUIRED_LINK_OPTIONS)
  if(NOT ORBED_VPTR_MEMBER_CALL_WORKS)
    message(WARNING "${CMAKE_CXX_COMPILER_ID} ${CMAKE_CXX_COMPILER_VERSION} miscompiles -fsanitize=vptr "
                    "on pointer-to-member calls (cmake/OrbedSanitizers.cmake): vptr checks off; "
                    "clang keeps them (CC=clang CXX=clang++)")
    add_compile_options(-fno-sanitize=vptr)
  endif()
endif()

set(ORBED_SANITIZER_ENV
    "ASAN_OPTIONS=detect_leaks=1:halt_on_error=1"
    "UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1"
    "LSAN_OPTIONS=suppressions=${PROJECT_SOURCE_DIR}/tests/lsan.supp:print_suppressions=0")
set(ORBED_SANITIZER_REPORT "ERROR: [A-Za-z]+Sanitizer" "SUMMARY: [A-Za-z]+Sanitizer" "runtime error: ")
