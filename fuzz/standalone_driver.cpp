// A small portable stand-in for libFuzzer, for compilers without it (GCC): replays the seed corpus,
// then mutates it deterministically (fixed seed) for a number of seconds or runs. No coverage
// feedback: mutations are stacked on recent inputs instead, and numeric fields are replaced with
// the values readers mishandle (NaN, inf, huge, negative, denormal).
//
//   TARGET [--seconds S] [--runs N] [--seed K] [--timeout S] [--max-len BYTES]
//          [--crash-dir DIR] CORPUS_DIR_OR_FILE...
//
// A crash (signal), a hang (> --timeout CPU seconds for one input: CPU time, so that a loaded
// machine does not make a slow input look like a hang) or an uncaught exception (abort
// through std::terminate) saves the input as CRASH_DIR/crash-<target>-<pid> and exits 1 with a
// message; a clean finish prints the counts and exits 0. A file argument with no mutation budget
// (--runs 0) just replays it, as libFuzzer does for a reproducer.
#include <fcntl.h>
#include <signal.h>
#include <sys/time.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

using Bytes = std::string;

// state read by the signal handler: the input under test, and where to save it
const char* g_current = nullptr;
std::size_t g_current_size = 0;
char g_crash_path[4096] = {0};
volatile sig_atomic_t g_in_input = 0;

void writeAll(int fd, const char* p, std::size_t n) {
  while (n > 0) {
    const ssize_t w = ::write(fd, p, n);
    if (w <= 0) return;
    p += w;
    n -= static_cast<std::size_t>(w);
  }
}

void onSignal(int sig) {
  // async-signal-safe only: open/write/close/_exit
  const char* what = sig == SIGPROF ? "hang (timeout)" : "crash (signal)";
  writeAll(2, "\n==fuzz== ", 10);
  writeAll(2, what, std::strlen(what));
  if (g_in_input && g_current != nullptr) {
    const int fd = ::open(g_crash_path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) {
      writeAll(fd, g_current, g_current_size);
      ::close(fd);
    }
    writeAll(2, "; input saved to ", 17);
    writeAll(2, g_crash_path, std::strlen(g_crash_path));
  }
  writeAll(2, "\n", 1);
  ::_exit(1);
}

void runOne(const Bytes& in, double timeout_s) {
  g_current = in.data();
  g_current_size = in.size();
  g_in_input = 1;
  itimerval t{};
  t.it_value.tv_sec = static_cast<time_t>(timeout_s);
  t.it_value.tv_usec = static_cast<suseconds_t>((timeout_s - static_cast<double>(t.it_value.tv_sec)) * 1e6);
  ::setitimer(ITIMER_PROF, &t, nullptr);
  LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(in.data()), in.size());
  itimerval off{};
  ::setitimer(ITIMER_PROF, &off, nullptr);
  g_in_input = 0;
}

bool readFile(const std::filesystem::path& p, Bytes& out) {
  std::ifstream f(p, std::ios::binary);
  if (!f) return false;
  out.assign(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
  return true;
}

// ---- mutations ---------------------------------------------------------------------------------

const char* const kNumbers[] = {"nan", "NaN", "-nan", "inf", "-inf", "Infinity", "1e308", "-1e308",
                                "1e400", "-1e400", "4.9e-324", "1e-320", "-1", "-0", "0", "-1e-9",
                                "2147483647", "2147483648", "-2147483649", "9223372036854775808",
                                "1e19", "3.4028235e38", "0x10", "1.5.5", "1e", "+", "-", ".", ""};
const char* const kTokens[] = {"<", ">", "</", "/>", "\"", "'", "&", "&amp;", "<!--", "-->",
                               "<![CDATA[", "]]>", "\n", "\t", " ", "=", "\0", "\xff", "\xc3",
                               "endheader\n", "version=1\n", "nRows=", "nColumns=", "inDegrees=yes\n",
                               "/bodyset/", "/ground", "<objects>", "</objects>", "time\t"};

bool isNumChar(char c) {
  return (c >= '0' && c <= '9') || c == '.' || c == '-' || c == '+' || c == 'e' || c == 'E';
}

class Mutator {
 public:
  Mutator(std::uint64_t seed, std::size_t max_len) : rng_(seed), max_len_(max_len) {}

  std::size_t below(std::size_t n) { return n == 0 ? 0 : static_cast<std::size_t>(rng_() % n); }

  void mutate(Bytes& b, const std::vector<Bytes>& pool) {
    const int n_ops = 1 + static_cast<int>(below(4));
    for (int k = 0; k < n_ops; ++k) mutateOnce(b, pool);
    if (b.size() > max_len_) b.resize(max_len_);
  }

 private:
  void mutateOnce(Bytes& b, const std::vector<Bytes>& pool) {
    switch (below(12)) {
      case 0:  // bit flip
        if (!b.empty()) b[below(b.size())] ^= static_cast<char>(1u << below(8));
        break;
      case 1:  // random byte
        if (!b.empty()) b[below(b.size())] = static_cast<char>(below(256));
        break;
      case 2: {  // insert random bytes
        const std::size_t n = 1 + below(8);
        Bytes ins;
        for (std::size_t i = 0; i < n; ++i) ins.push_back(static_cast<char>(below(256)));
        b.insert(below(b.size() + 1), ins);
        break;
      }
      case 3: {  // delete a range
        if (b.empty()) break;
        const std::size_t at = below(b.size());
        b.erase(at, 1 + below(std::min<std::size_t>(64, b.size() - at)));
        break;
      }
      case 4:  // truncate
        b.resize(below(b.size() + 1));
        break;
      case 5: {  // splice: head of this one, tail of another
        const Bytes& o = pool[below(pool.size())];
        const std::size_t a = below(b.size() + 1), c = below(o.size() + 1);
        b = b.substr(0, a) + o.substr(c);
        break;
      }
      case 6:
      case 7:
      case 8: {  // replace a numeric field
        if (b.empty()) break;
        std::size_t at = below(b.size());
        std::size_t tries = 0;
        while (tries++ < b.size() && !(b[at] >= '0' && b[at] <= '9')) at = (at + 1) % b.size();
        if (!(b[at] >= '0' && b[at] <= '9')) break;
        std::size_t lo = at, hi = at;
        while (lo > 0 && isNumChar(b[lo - 1])) --lo;
        while (hi < b.size() && isNumChar(b[hi])) ++hi;
        b.replace(lo, hi - lo, kNumbers[below(std::size(kNumbers))]);
        break;
      }
      case 9: {  // insert a token
        const char* t = kTokens[below(std::size(kTokens))];
        b.insert(below(b.size() + 1), Bytes(t, std::max<std::size_t>(1, std::strlen(t))));
        break;
      }
      case 10: {  // delete or duplicate a line
        std::vector<std::size_t> starts{0};
        for (std::size_t i = 0; i < b.size(); ++i)
          if (b[i] == '\n') starts.push_back(i + 1);
        const std::size_t l = below(starts.size());
        const std::size_t s = starts[l];
        const std::size_t e = l + 1 < starts.size() ? starts[l + 1] : b.size();
        const Bytes line = b.substr(s, e - s);
        if (below(2)) {
          b.erase(s, e - s);
        } else {
          b.insert(starts[below(starts.size())], line);
        }
        break;
      }
      case 11: {  // copy a line from another input of the pool (XML elements between files)
        const Bytes& o = pool[below(pool.size())];
        std::vector<std::size_t> starts{0};
        for (std::size_t i = 0; i < o.size(); ++i)
          if (o[i] == '\n') starts.push_back(i + 1);
        const std::size_t l = below(starts.size());
        const std::size_t e = l + 1 < starts.size() ? starts[l + 1] : o.size();
        std::size_t at = below(b.size() + 1);
        while (at > 0 && at < b.size() && b[at - 1] != '\n') --at;
        b.insert(at, o.substr(starts[l], e - starts[l]));
        break;
      }
    }
  }

  std::mt19937_64 rng_;
  std::size_t max_len_;
};

[[noreturn]] void usage(const char* argv0, const std::string& why) {
  std::fprintf(stderr,
               "error: %s\nusage: %s [--seconds S] [--runs N] [--seed K] [--timeout S] "
               "[--max-len BYTES] [--crash-dir DIR] CORPUS_DIR_OR_FILE...\n",
               why.c_str(), argv0);
  std::exit(2);
}

}  // namespace

int main(int argc, char** argv) {
  double seconds = -1.0, timeout = 2.0;
  long long runs = -1;
  std::uint64_t seed = 1;
  std::size_t max_len = 1 << 20;
  std::string crash_dir = ".";
  std::vector<std::string> inputs;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) usage(argv[0], a + " needs a value");
      return argv[++i];
    };
    try {
      if (a == "--seconds") seconds = std::stod(value());
      else if (a == "--runs") runs = std::stoll(value());
      else if (a == "--seed") seed = std::stoull(value());
      else if (a == "--timeout") timeout = std::stod(value());
      else if (a == "--max-len") max_len = std::stoull(value());
      else if (a == "--crash-dir") crash_dir = value();
      else if (a.rfind("--", 0) == 0) usage(argv[0], "unknown flag " + a);
      else inputs.push_back(a);
    } catch (const std::logic_error&) {
      usage(argv[0], "bad value for " + a);
    }
  }
  if (inputs.empty()) usage(argv[0], "no corpus given");
  if (!(timeout > 0.0)) usage(argv[0], "--timeout must be positive");

  // corpus: files, and the regular files of folders (recursively), in sorted order
  std::vector<std::filesystem::path> files;
  for (const auto& in : inputs) {
    std::error_code ec;
    if (std::filesystem::is_directory(in, ec)) {
      for (const auto& e : std::filesystem::recursive_directory_iterator(in, ec))
        if (e.is_regular_file()) files.push_back(e.path());
    } else if (std::filesystem::is_regular_file(in, ec)) {
      files.emplace_back(in);
    } else {
      usage(argv[0], "no such file or folder: " + in);
    }
  }
  std::sort(files.begin(), files.end());
  std::vector<Bytes> corpus;
  for (const auto& f : files) {
    Bytes b;
    if (!readFile(f, b)) usage(argv[0], "cannot read " + f.string());
    corpus.push_back(b);
  }
  if (corpus.empty()) corpus.emplace_back();

  const std::string target = std::filesystem::path(argv[0]).filename().string();
  std::snprintf(g_crash_path, sizeof g_crash_path, "%s/crash-%s-%d", crash_dir.c_str(),
                target.c_str(), static_cast<int>(::getpid()));
  for (int sig : {SIGSEGV, SIGABRT, SIGFPE, SIGBUS, SIGILL, SIGPROF}) ::signal(sig, onSignal);

  const auto t_start = std::chrono::steady_clock::now();
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  };
  long long executed = 0;
  for (const auto& b : corpus) {
    runOne(b, timeout);
    ++executed;
  }
  std::fprintf(stderr, "==fuzz== %s: replayed %zu corpus inputs in %.2f s\n", target.c_str(),
               corpus.size(), elapsed());
  if (seconds < 0.0 && runs < 0) runs = 0;  // nothing asked: replay only

  Mutator mut(seed, max_len);
  std::vector<Bytes> recent;  // inputs to stack further mutations on
  double last_report = 0.0;
  long long mutated = 0;
  while ((runs < 0 || mutated < runs) && (seconds < 0.0 || elapsed() < seconds)) {
    Bytes b = (!recent.empty() && mut.below(3) == 0) ? recent[mut.below(recent.size())]
                                                     : corpus[mut.below(corpus.size())];
    mut.mutate(b, corpus);
    runOne(b, timeout);
    ++mutated;
    if (recent.size() < 256) recent.push_back(std::move(b));
    else recent[mut.below(recent.size())] = std::move(b);
    if (elapsed() - last_report > 60.0) {
      last_report = elapsed();
      std::fprintf(stderr, "==fuzz== %s: %lld mutated inputs, %.0f s\n", target.c_str(), mutated,
                   last_report);
    }
  }
  executed += mutated;
  std::fprintf(stderr, "==fuzz== %s: done, %lld inputs (%lld mutated) in %.1f s, no crash\n",
               target.c_str(), executed, mutated, elapsed());
  return 0;
}
