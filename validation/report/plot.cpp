#include "validation/report/plot.hpp"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>
#include <thread>

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "validation/report/json_value.hpp"

extern char** environ;

namespace redmax::validation {
namespace {

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------------------------
// running gnuplot

struct ProcessResult {
  int status = -1;       // exit status; -1 not started, -2 killed after the timeout
  std::string output;    // stdout and stderr together
  std::string spawn_error;
};

std::string readWholeFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// run argv[0] (a path) with stdin from /dev/null and stdout+stderr into a temporary file; no
// shell is involved, so no argument is ever interpreted
ProcessResult runProcess(const std::vector<std::string>& argv, double timeout_s) {
  ProcessResult r;
  std::string log = (fs::temp_directory_path() / "redmax_gnuplot_XXXXXX").string();
  const int fd = ::mkstemp(log.data());
  if (fd < 0) {
    r.spawn_error = std::string("cannot create a temporary file: ") + std::strerror(errno);
    return r;
  }
  ::close(fd);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&fa, 1, log.c_str(), O_WRONLY | O_TRUNC, 0600);
  posix_spawn_file_actions_adddup2(&fa, 1, 2);
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = 0;
  const int rc = ::posix_spawn(&pid, argv[0].c_str(), &fa, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) {
    r.spawn_error = "cannot run " + argv[0] + ": " + std::strerror(rc);
    std::remove(log.c_str());
    return r;
  }
  // wait, polling so that a hung gnuplot can be killed
  const auto t_end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  int wstatus = 0;
  for (;;) {
    const pid_t w = ::waitpid(pid, &wstatus, WNOHANG);
    if (w == pid) break;
    if (w < 0 && errno != EINTR) {
      wstatus = -1;
      break;
    }
    if (std::chrono::steady_clock::now() > t_end) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &wstatus, 0);
      r.status = -2;
      r.output = readWholeFile(log);
      std::remove(log.c_str());
      return r;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  r.status = (wstatus != -1 && WIFEXITED(wstatus)) ? WEXITSTATUS(wstatus) : 128;
  r.output = readWholeFile(log);
  std::remove(log.c_str());
  return r;
}

bool isExecutableFile(const std::string& p) {
  struct stat st {};
  return ::stat(p.c_str(), &st) == 0 && S_ISREG(st.st_mode) && ::access(p.c_str(), X_OK) == 0;
}

std::string searchPath(const std::string& name) {
  if (name.find('/') != std::string::npos) return isExecutableFile(name) ? name : "";
  const char* path = std::getenv("PATH");
  std::stringstream ss(path ? path : "/usr/local/bin:/usr/bin:/bin");
  std::string dir;
  while (std::getline(ss, dir, ':')) {
    if (dir.empty()) dir = ".";
    const std::string p = dir + "/" + name;
    if (isExecutableFile(p)) return p;
  }
  return "";
}

GnuplotInfo probeGnuplot(const std::string& exe) {
  GnuplotInfo gp;
  gp.path = exe;
  const auto r = runProcess({exe, "-e", "print GPVAL_VERSION, GPVAL_PATCHLEVEL; print GPVAL_TERMINALS"}, 30);
  if (r.status != 0) {
    gp.why_not = exe + " does not run" + (r.spawn_error.empty() ? "" : ": " + r.spawn_error);
    return gp;
  }
  std::istringstream in(r.output);
  std::string first;
  std::getline(in, first);
  double version = 0;
  std::string patch;
  std::istringstream(first) >> version >> patch;
  std::ostringstream v;
  v << version << (patch.empty() ? "" : "." + patch);
  gp.version = v.str();
  std::string term, terms = " ";
  while (in >> term) terms += term + " ";
  gp.pngcairo = terms.find(" pngcairo ") != std::string::npos;
  gp.svg = terms.find(" svg ") != std::string::npos;
  if (version < 5.0) {
    gp.why_not = "gnuplot " + gp.version + " is older than 5.0 (no datablocks)";
  } else if (!gp.pngcairo && !gp.svg) {
    gp.why_not = "gnuplot " + gp.version + " has neither the pngcairo nor the svg terminal";
  } else {
    gp.available = true;
  }
  return gp;
}

// ---------------------------------------------------------------------------------------------
// script generation

// a gnuplot single-quoted string: nothing inside is substituted; '' stands for one quote
std::string quoteGp(const std::string& s) {
  std::string o = "'";
  for (char c : s) {
    if (c == '\'') o += "''";
    else if (c == '\n' || c == '\r' || c == '\t') o += ' ';
    else o += c;
  }
  return o + "'";
}

std::string dataValue(double v, bool log_axis) {
  if (!std::isfinite(v) || (log_axis && !(v > 0))) return "NaN";
  return formatNumber(v);
}

bool hasDrawablePoint(const PlotLine& l, bool log_x, bool log_y) {
  const size_t n = std::min(l.x.size(), l.y.size());
  for (size_t i = 0; i < n; ++i) {
    const bool ok_x = std::isfinite(l.x[i]) && (!log_x || l.x[i] > 0);
    const bool ok_y = std::isfinite(l.y[i]) && (!log_y || l.y[i] > 0);
    if (ok_x && ok_y) return true;
  }
  return false;
}

int gridColumns(const PlotFigure& fig) {
  const int n = static_cast<int>(fig.panels.size());
  if (fig.columns > 0) return std::min(fig.columns, std::max(n, 1));
  if (n <= 1) return 1;
  if (n <= 4) return 2;
  if (n <= 9) return 3;
  return 4;
}

std::atomic<unsigned> g_plot_counter{0};

}  // namespace

GnuplotInfo findGnuplot(const std::string& hint) {
  std::string want = hint;
  if (want.empty()) {
    const char* env = std::getenv("REDMAX_GNUPLOT");
    want = (env && *env) ? env : "gnuplot";
  }
  if (want == "none") {
    GnuplotInfo gp;
    gp.why_not = "plots disabled";
    return gp;
  }
  const std::string exe = searchPath(want);
  if (exe.empty()) {
    GnuplotInfo gp;
    gp.why_not = want == "gnuplot" ? "gnuplot not found on PATH" : "gnuplot executable '" + want + "' not found";
    return gp;
  }
  // probing spawns a process: remember the answer per executable
  static std::mutex mutex;
  static std::map<std::string, GnuplotInfo> cache;
  std::lock_guard<std::mutex> lock(mutex);
  const auto it = cache.find(exe);
  if (it != cache.end()) return it->second;
  return cache[exe] = probeGnuplot(exe);
}

std::string resolvePlotExtension(const GnuplotInfo& gp, PlotFormat format) {
  if (!gp.available) return "";
  if (format == PlotFormat::Svg) return gp.svg ? "svg" : "png";
  // Png and Auto: pngcairo if present, SVG as the fallback
  return gp.pngcairo ? "png" : "svg";
}

std::string makeGnuplotScript(const PlotFigure& fig, const std::string& extension, const std::string& output_path) {
  const int n_panels = static_cast<int>(fig.panels.size());
  const int cols = gridColumns(fig);
  const int rows = std::max(1, (n_panels + cols - 1) / cols);
  const int title_px = fig.title.empty() ? 0 : 30;
  const int w = cols * std::max(fig.panel_width, 100);
  const int h = rows * std::max(fig.panel_height, 80) + title_px;
  std::ostringstream s;
  s << "# generated by redmax (validation/report/plot.cpp)\n";
  // noenhanced: column names such as hip_flexion_r_moment must not turn into subscripts
  if (extension == "svg") {
    s << "set terminal svg noenhanced size " << w << "," << h << " font 'sans,10' background '#ffffff'\n";
  } else {
    s << "set terminal pngcairo noenhanced size " << w << "," << h << " font 'sans,9'\n";
  }
  s << "set output " << quoteGp(output_path) << "\n";
  s << "set encoding utf8\n";

  // data as datablocks, one per drawable line
  for (int p = 0; p < n_panels; ++p) {
    const auto& panel = fig.panels[p];
    for (size_t l = 0; l < panel.lines.size(); ++l) {
      const auto& line = panel.lines[l];
      if (!hasDrawablePoint(line, panel.log_x, panel.log_y)) continue;
      s << "$d_" << p << "_" << l << " << EOD\n";
      const size_t n = std::min(line.x.size(), line.y.size());
      for (size_t i = 0; i < n; ++i) {
        s << dataValue(line.x[i], panel.log_x) << " " << dataValue(line.y[i], panel.log_y) << "\n";
      }
      s << "EOD\n";
    }
  }

  s << "set multiplot layout " << rows << "," << cols;
  if (!fig.title.empty()) s << " title " << quoteGp(fig.title) << " font ',12'";
  s << "\n";
  s << "set grid\n";
  for (int p = 0; p < n_panels; ++p) {
    const auto& panel = fig.panels[p];
    // every panel sets all its state: nothing leaks from the previous one
    s << "set title " << quoteGp(panel.title) << "\n";
    s << "set xlabel " << quoteGp(panel.xlabel) << "\nset ylabel " << quoteGp(panel.ylabel) << "\n";
    s << "unset logscale\nset autoscale\nunset label\nset xtics\nset ytics\n";
    // the legend over an opaque box, so that it stays legible over the curves
    if (panel.key == "off") {
      s << "unset key\n";
    } else {
      std::string where;
      for (char c : panel.key) where += (std::isalpha(static_cast<unsigned char>(c)) || c == ' ') ? c : ' ';
      s << "set key " << where << " opaque box font ',8'\n";
    }
    // decades as 0.001, 1e-05 (noenhanced text cannot draw superscripts)
    if (panel.log_x) s << "set logscale x\nset format x '%g'\n";
    else s << "set format x '% h'\n";
    if (panel.log_y) s << "set logscale y\nset format y '%g'\n";
    else s << "set format y '% h'\n";
    std::vector<std::string> items;
    for (size_t l = 0; l < panel.lines.size(); ++l) {
      const auto& line = panel.lines[l];
      if (!hasDrawablePoint(line, panel.log_x, panel.log_y)) continue;
      std::ostringstream it;
      it << "$d_" << p << "_" << l << " using 1:2 with " << (line.style.empty() ? "lines" : line.style);
      if (line.style != "points") it << " dt " << std::max(1, line.dash_type) << " lw " << line.width;
      it << " lc " << (l + 1);
      if (line.label.empty()) it << " notitle";
      else it << " title " << quoteGp(line.label);
      items.push_back(it.str());
    }
    if (items.empty()) {
      // an empty panel still takes its place in the grid, saying why it is empty
      s << "unset logscale\nset xrange [0:1]\nset yrange [0:1]\nunset xtics\nunset ytics\n";
      s << "set label 1 'no data' at 0.5,0.5 center\nplot 2 notitle\n";
      continue;
    }
    s << "plot ";
    for (size_t i = 0; i < items.size(); ++i) s << (i ? ", \\\n     " : "") << items[i];
    s << "\n";
  }
  s << "unset multiplot\nset output\n";
  return s.str();
}

PlotOutcome renderPlot(const GnuplotInfo& gp, PlotFormat format, const PlotFigure& fig, const std::string& path_stem,
                       double timeout_s) {
  PlotOutcome out;
  const std::string ext = resolvePlotExtension(gp, format);
  if (ext.empty()) {
    out.error = gp.why_not.empty() ? "gnuplot is not available" : gp.why_not;
    return out;
  }
  if (fig.panels.empty()) {
    out.error = "figure has no panel";
    return out;
  }
  const std::string target = path_stem + "." + ext;
  const std::string tag = std::to_string(::getpid()) + "." + std::to_string(g_plot_counter++);
  // the image goes to a temporary name beside the target, renamed only when gnuplot succeeded
  const std::string tmp_image = target + ".tmp." + tag;
  std::string script_path = (fs::temp_directory_path() / "redmax_plot_XXXXXX").string();
  const int fd = ::mkstemp(script_path.data());
  if (fd < 0) {
    out.error = std::string("cannot create a temporary script: ") + std::strerror(errno);
    return out;
  }
  ::close(fd);
  {
    std::ofstream f(script_path, std::ios::binary);
    f << makeGnuplotScript(fig, ext, tmp_image);
    if (!f) {
      std::remove(script_path.c_str());
      out.error = "cannot write the temporary script " + script_path;
      return out;
    }
  }
  const auto r = runProcess({gp.path, script_path}, timeout_s);
  std::remove(script_path.c_str());

  std::error_code ec;
  const bool made = fs::exists(tmp_image, ec) && fs::file_size(tmp_image, ec) > 0;
  if (r.status != 0 || !made) {
    fs::remove(tmp_image, ec);
    if (!r.spawn_error.empty()) {
      out.error = r.spawn_error;
    } else if (r.status == -2) {
      out.error = "gnuplot did not finish within " + formatNumber(timeout_s) + " s";
    } else {
      // gnuplot's message: the first line that names an error (else the last non-empty line)
      std::istringstream in(r.output);
      std::string line, last, msg;
      while (std::getline(in, line)) {
        if (!line.empty() && line.find_first_not_of(" ^") != std::string::npos) last = line;
        if (msg.empty() && (line.find("error") != std::string::npos || line.find("line ") == 0)) msg = line;
      }
      out.error = "gnuplot failed (exit " + std::to_string(r.status) + ")" +
                  (msg.empty() ? (last.empty() ? std::string() : ": " + last) : ": " + msg);
    }
    return out;
  }
  if (std::rename(tmp_image.c_str(), target.c_str()) != 0) {
    out.error = "cannot write " + target + ": " + std::strerror(errno);
    fs::remove(tmp_image, ec);
    return out;
  }
  out.ok = true;
  out.file = target;
  return out;
}

// ---------------------------------------------------------------------------------------------
// figure builders

PlotLine makePlotLine(std::string label, std::vector<double> x, std::vector<double> y, std::string style) {
  PlotLine l;
  l.label = std::move(label);
  l.x = std::move(x);
  l.y = std::move(y);
  l.style = std::move(style);
  return l;
}

PlotPanel makeXYPanel(const std::string& title, const std::string& xlabel, const std::string& ylabel,
                      std::vector<PlotLine> lines) {
  PlotPanel p;
  p.title = title;
  p.xlabel = xlabel;
  p.ylabel = ylabel;
  p.lines = std::move(lines);
  return p;
}

PlotPanel makeLogLogPanel(const std::string& title, const std::string& xlabel, const std::string& ylabel,
                          std::vector<PlotLine> lines) {
  PlotPanel p = makeXYPanel(title, xlabel, ylabel, std::move(lines));
  p.log_x = p.log_y = true;
  p.key = "bottom left";  // work-precision curves fall from top left to bottom right
  for (auto& l : p.lines) {
    if (l.style == "lines") l.style = "linespoints";
  }
  return p;
}

std::vector<PlotFigure> makeColumnGridFigures(const SeriesSet& set, const std::string& title, const std::string& ylabel,
                                              int panels_per_figure) {
  std::vector<PlotFigure> figs;
  const int nc = static_cast<int>(set.columns.size());
  const int per = std::max(1, panels_per_figure);
  const int n_figs = (nc + per - 1) / per;
  for (int f = 0; f < n_figs; ++f) {
    PlotFigure fig;
    fig.title = title;
    if (n_figs > 1) fig.title += " (" + std::to_string(f + 1) + "/" + std::to_string(n_figs) + ")";
    for (int k = f * per; k < std::min(nc, (f + 1) * per); ++k) {
      PlotPanel panel;
      panel.title = set.columns[k];
      panel.xlabel = "time [s]";
      panel.ylabel = ylabel;
      for (size_t s = 0; s < set.values.size(); ++s) {
        PlotLine line;
        line.label = s < set.labels.size() ? set.labels[s] : "";
        line.x = set.time;
        line.y = set.values[s].at(k);
        // later series dashed and thinner, so that curves lying on top of each other stay visible
        // (dash types 1 solid, 2 dashed, then 4, 5... dash-dot patterns: 3's dots are too faint)
        line.dash_type = s < 2 ? static_cast<int>(s) + 1 : static_cast<int>(s) + 2;
        line.width = std::max(1.2, 2.5 - 0.6 * static_cast<double>(s));
        panel.lines.push_back(std::move(line));
      }
      fig.panels.push_back(std::move(panel));
    }
    figs.push_back(std::move(fig));
  }
  return figs;
}

}  // namespace redmax::validation
