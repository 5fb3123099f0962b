// Runs a fuzz target's LLVMFuzzerTestOneInput on files instead of under libFuzzer, for the
// regression corpus in ctest: every file named on the command line, and every file under the
// folders named. An input fails the run by aborting (a crash, a sanitizer report or an outcome
// the target does not accept), by taking longer than the time limit, or, outside sanitizer
// builds, by pushing the peak RSS over the memory limit.
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

namespace {

// The same limits as `make fuzz` (-timeout=20 -rss_limit_mb=1024).
constexpr unsigned kTimeoutSeconds = 20;
constexpr long kRssLimitMb = 1024;

const char* g_current = "";

void onAlarm(int) {
  const char msg[] = "fuzz regression: time limit exceeded on ";
  (void)!write(2, msg, sizeof msg - 1);
  (void)!write(2, g_current, std::char_traits<char>::length(g_current));
  (void)!write(2, "\n", 1);
  _exit(3);
}

long peakRssMb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss / 1024;
}

bool sanitized() {
#if defined(__SANITIZE_ADDRESS__)
  return true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
  return true;
#else
  return false;
#endif
#else
  return false;
#endif
}

}  // namespace

int main(int argc, char** argv) {
  namespace fs = std::filesystem;
  std::vector<fs::path> inputs;
  for (int i = 1; i < argc; ++i) {
    const fs::path p(argv[i]);
    if (fs::is_directory(p)) {
      for (const auto& e : fs::recursive_directory_iterator(p))
        if (e.is_regular_file()) inputs.push_back(e.path());
    } else if (fs::is_regular_file(p)) {
      inputs.push_back(p);
    } else {
      std::fprintf(stderr, "fuzz regression: %s: no such file or folder\n", argv[i]);
      return 2;
    }
  }
  std::sort(inputs.begin(), inputs.end());
  if (inputs.empty()) {
    std::fprintf(stderr, "fuzz regression: no inputs\n");
    return 2;
  }
  std::signal(SIGALRM, onAlarm);
  for (const auto& p : inputs) {
    std::ifstream in(p, std::ios::binary);
    const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), {});
    const std::string name = p.string();
    g_current = name.c_str();
    std::fprintf(stderr, "%s (%zu bytes)\n", name.c_str(), bytes.size());
    alarm(kTimeoutSeconds);
    LLVMFuzzerTestOneInput(bytes.data(), bytes.size());
    alarm(0);
    // ASan's shadow memory counts in the RSS; its builds are checked by the fuzzer's own limit.
    if (!sanitized() && peakRssMb() > kRssLimitMb) {
      std::fprintf(stderr, "fuzz regression: peak RSS %ld MB over %ld MB after %s\n", peakRssMb(), kRssLimitMb, name.c_str());
      return 1;
    }
  }
  std::printf("%zu inputs, peak RSS %ld MB\n", inputs.size(), peakRssMb());
  return 0;
}
