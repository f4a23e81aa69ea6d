// `redmax batch`: a study of many redmax runs on a Dask cluster. The work is Python
// (python/redmax/study.py over Debian's python3-distributed, its report python/redmax/report.py);
// this command checks the flags and execs it with the Python interpreter, passing this executable
// as $REDMAX_EXE so the tasks run the same build. docs/python.md §3 has the study contract.
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "cli/flags.hpp"

#ifndef REDMAX_PYTHON
#define REDMAX_PYTHON "/usr/bin/python3"
#endif
#ifndef REDMAX_SOURCE_DIR
#define REDMAX_SOURCE_DIR ""
#endif

namespace redmax::cli {
namespace {

namespace fs = std::filesystem;

struct BatchFlags {
  std::vector<std::string> study;
  std::string scheduler, out;
  long workers = 0;
  bool serial = false;
};

// study.py beside the executable's build tree (build/python/redmax/, what CMake copies), else in
// the source tree this executable was built from
std::string findBatchScript(const fs::path& exe) {
  const std::vector<fs::path> candidates = {exe.parent_path() / ".." / "python" / "redmax" / "study.py",
                                            fs::path(REDMAX_SOURCE_DIR) / "python" / "redmax" / "study.py"};
  for (const auto& c : candidates) {
    std::error_code ec;
    if (fs::is_regular_file(c, ec)) return fs::weakly_canonical(c).string();
  }
  return "";
}

int runBatch(const BatchFlags& f, const CLI::App& app) {
  if (f.study.size() != 1) throw UsageError{f.study.empty() ? "batch needs a STUDY.json" : "batch takes one STUDY.json"};
  if (!given(app, "--out")) throw UsageError{"batch needs --out DIR"};
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  const std::string script = findBatchScript(ec ? fs::path() : exe);
  if (script.empty()) {
    std::cerr << "error: python/redmax/study.py not found beside " << exe.string() << " or in " << REDMAX_SOURCE_DIR
              << "\n";
    return 2;
  }
  const char* py_env = std::getenv("REDMAX_PYTHON");
  const std::string python = py_env && *py_env ? py_env : REDMAX_PYTHON;
  if (!ec) setenv("REDMAX_EXE", exe.c_str(), 1);

  std::vector<std::string> args = {python, script, f.study[0], "--out", f.out};
  if (given(app, "--scheduler")) args.insert(args.end(), {"--scheduler", f.scheduler});
  if (given(app, "--workers")) args.insert(args.end(), {"--workers", std::to_string(f.workers)});
  if (f.serial) args.push_back("--serial");
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::cout.flush();
  execv(python.c_str(), argv.data());
  std::cerr << "error: " << python << ": " << std::strerror(errno)
            << " (redmax batch needs Python 3 with python3-distributed; set REDMAX_PYTHON)\n";
  return 2;
}

CommandRegistration reg(
    {"batch", "run a study (many redmax runs over a grid of flags) on a Dask cluster", [](CLI::App& app) {
       auto f = std::make_shared<BatchFlags>();
       app.add_option("STUDY", f->study, "the study (.json): trials and the grid of flags")
           ->type_name("STUDY.json")
           ->check(existingFile())
           ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
       app.add_option("--scheduler", f->scheduler, "an existing Dask scheduler (default: a local cluster)")
           ->type_name("ADDRESS");
       app.add_option("--workers", f->workers, "local cluster: worker processes (default: the cores)")
           ->type_name("N")
           ->check(positive());
       app.add_flag("--serial", f->serial, "run the cells one after another without Dask (the reference)");
       app.add_option("--out", f->out, "the study folder: DIR/results.csv, DIR/<trial>/<cell>/ (required)")
           ->type_name("DIR");
       app.footer(
           "usage: redmax batch STUDY.json [--scheduler ADDRESS] [--workers N] [--serial] --out DIR\n"
           "STUDY.json: {\"trials\": [{\"name\", \"command\", \"args\": [...]}], \"grid\": {\"--flag\": [values]}}.\n"
           "Each trial is a redmax command with its arguments (relative paths resolved against the\n"
           "study file); the grid's flags are crossed and appended; the command's output flag\n"
           "(--out-dir, --out or --report) is added, pointing into DIR/<trial>/<cell>/. Each cell is a\n"
           "Dask task. DIR/results.csv: trial, cell, each grid flag, status (ok|error), error, wall_s,\n"
           "output, then the summary figures the commands print (and results.parquet where pyarrow\n"
           "is installed). DIR/report.md: every cell, and SVG figures (gnuplot) of the numeric\n"
           "columns against each grid flag in DIR/report/. Outputs are written atomically; a\n"
           "rerun skips complete cells. Progress on stderr. Runs python/redmax/study.py with\n"
           "$REDMAX_PYTHON (default " REDMAX_PYTHON ").\n"
           "Exit codes: 0 every cell ok, 1 some cell failed (the rest complete), 2 bad input or usage.");
       return [f, &app] { return runBatch(*f, app); };
     }});

}  // namespace
}  // namespace redmax::cli
