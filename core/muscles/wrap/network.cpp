#include "core/muscles/wrap/network.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

namespace redmax {
namespace {

// uniform double in [0, 1) from the top 53 bits (portable, unlike std::uniform_real_distribution)
double uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

std::string fmt17(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

void appendVector(std::ostringstream& os, const char* key, const VecX& v) {
  os << key;
  for (Eigen::Index i = 0; i < v.size(); ++i) os << ' ' << fmt17(v[i]);
  os << '\n';
}

bool bitEqual(const MatX& a, const MatX& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() &&
         (a.size() == 0 || std::memcmp(a.data(), b.data(), sizeof(double) * a.size()) == 0);
}
bool bitEqual(const VecX& a, const VecX& b) {
  return a.size() == b.size() && (a.size() == 0 || std::memcmp(a.data(), b.data(), sizeof(double) * a.size()) == 0);
}

}  // namespace

Mlp::Mlp(int n_in, const std::vector<int>& hidden, int n_out, unsigned long long seed)
    : n_in_(n_in), n_out_(n_out), hidden_(hidden) {
  if (n_in < 1 || n_out < 1 || hidden.empty()) throw std::invalid_argument("Mlp: needs inputs, outputs and at least one hidden layer");
  for (int h : hidden)
    if (h < 1) throw std::invalid_argument("Mlp: hidden layer widths must be positive");
  std::mt19937_64 rng(seed);
  std::vector<int> sizes{n_in};
  sizes.insert(sizes.end(), hidden.begin(), hidden.end());
  sizes.push_back(n_out);
  for (std::size_t l = 0; l + 1 < sizes.size(); ++l) {
    // glorot-uniform: keeps tanh pre-activations O(1) at any width
    const double a = std::sqrt(6.0 / (sizes[l] + sizes[l + 1]));
    MatX W(sizes[l + 1], sizes[l]);
    for (Eigen::Index j = 0; j < W.cols(); ++j)
      for (Eigen::Index i = 0; i < W.rows(); ++i) W(i, j) = a * (2.0 * uniform01(rng) - 1.0);
    W_.push_back(W);
    b_.push_back(VecX::Zero(sizes[l + 1]));
  }
  input_mean = VecX::Zero(n_in);
  input_scale = VecX::Ones(n_in);
  output_mean = VecX::Zero(n_out);
  output_scale = VecX::Ones(n_out);
  input_min = VecX::Constant(n_in, -1.0);
  input_max = VecX::Constant(n_in, 1.0);
  for (int i = 0; i < n_in; ++i) input_names.push_back("x" + std::to_string(i));
  for (int i = 0; i < n_out; ++i) output_names.push_back("y" + std::to_string(i));
}

long Mlp::parameterCount() const {
  long n = 0;
  for (std::size_t l = 0; l < W_.size(); ++l) n += W_[l].size() + b_[l].size();
  return n;
}

std::string Mlp::architecture() const {
  bool uniform = true;
  for (int h : hidden_) uniform = uniform && h == hidden_.front();
  if (uniform) return std::to_string(hidden_.size()) + "x" + std::to_string(hidden_.front());
  std::string s;
  for (std::size_t i = 0; i < hidden_.size(); ++i) s += (i ? "-" : "") + std::to_string(hidden_[i]);
  return s;
}

void Mlp::forwardHidden(const MatX& X, const MatX* Xdot, MlpWorkspace& ws) const {
  if (X.rows() != n_in_) throw std::invalid_argument("Mlp: input has " + std::to_string(X.rows()) + " rows, expected " + std::to_string(n_in_));
  const int L = static_cast<int>(hidden_.size());
  ws.H.resize(L);
  ws.Hdot.resize(L);
  const VecX inv_scale = input_scale.cwiseInverse();
  ws.U.noalias() = (X.colwise() - input_mean);
  ws.U.array().colwise() *= inv_scale.array();
  if (Xdot) {
    ws.Udot = *Xdot;
    ws.Udot.array().colwise() *= inv_scale.array();
  }
  for (int l = 0; l < L; ++l) {
    const MatX& prev = l == 0 ? ws.U : ws.H[l - 1];
    ws.H[l].noalias() = W_[l] * prev;
    ws.H[l].colwise() += b_[l];
    ws.H[l] = ws.H[l].array().tanh();
    if (Xdot) {
      // tangent: hdot = (1 - h^2) .* (W hdot_prev)
      const MatX& prev_dot = l == 0 ? ws.Udot : ws.Hdot[l - 1];
      ws.Hdot[l].noalias() = W_[l] * prev_dot;
      ws.Hdot[l].array() *= 1.0 - ws.H[l].array().square();
    }
  }
}

void Mlp::outputLayer(const MlpWorkspace& ws, MatX& Y) const {
  Y.noalias() = W_.back() * ws.H.back();
  Y.colwise() += b_.back();
  Y.array().colwise() *= output_scale.array();
  Y.colwise() += output_mean;
}

void Mlp::reverse(int N, bool with_dot, MatX& J, MatX* Jdot, MlpWorkspace& ws) const {
  // adjoints of all outputs k at once: columns [k N, (k+1) N) belong to output k, and with_dot
  // appends their time derivatives in the next n_out N columns
  const int L = static_cast<int>(hidden_.size());
  const int KN = n_out_ * N;
  const int C = with_dot ? 2 * KN : KN;
  const MatX& Wl = W_.back();
  const int nL = hidden_.back();
  ws.G.resize(nL, C);
  {
    const auto d = 1.0 - ws.H[L - 1].array().square();  // tanh' = 1 - tanh^2
    for (int k = 0; k < n_out_; ++k) {
      ws.G.middleCols(k * N, N).array() = d.colwise() * Wl.row(k).transpose().array();
      if (with_dot) {
        // d/dt (1 - h^2) = -2 h hdot
        ws.G.middleCols(KN + k * N, N).array() =
            (-2.0 * ws.H[L - 1].array() * ws.Hdot[L - 1].array()).colwise() * Wl.row(k).transpose().array();
      }
    }
  }
  for (int l = L - 1; l >= 1; --l) {
    // [G | Gdot]_{l-1} from W_l^T [G | Gdot]_l, scaled by tanh' (and its derivative)
    ws.A.noalias() = W_[l].transpose() * ws.G;
    const auto& h = ws.H[l - 1].array();
    ws.G.resize(hidden_[l - 1], C);
    for (int k = 0; k < n_out_; ++k) {
      auto a = ws.A.middleCols(k * N, N).array();
      ws.G.middleCols(k * N, N).array() = a * (1.0 - h.square());
      if (with_dot) {
        const auto& hd = ws.Hdot[l - 1].array();
        ws.G.middleCols(KN + k * N, N).array() =
            ws.A.middleCols(KN + k * N, N).array() * (1.0 - h.square()) - 2.0 * a * h * hd;
      }
    }
  }
  ws.Jt.noalias() = W_[0].transpose() * ws.G;
  // scatter to J (n_out x n_in N) in raw units: diag(output_scale) J_u diag(1 / input_scale)
  J.resize(n_out_, static_cast<Eigen::Index>(n_in_) * N);
  if (with_dot) Jdot->resize(n_out_, static_cast<Eigen::Index>(n_in_) * N);
  for (int p = 0; p < N; ++p)
    for (int i = 0; i < n_in_; ++i)
      for (int k = 0; k < n_out_; ++k) {
        const double s = output_scale[k] / input_scale[i];
        J(k, p * n_in_ + i) = s * ws.Jt(i, k * N + p);
        if (with_dot) (*Jdot)(k, p * n_in_ + i) = s * ws.Jt(i, KN + k * N + p);
      }
}

void Mlp::calcOutput(const MatX& X, MatX& Y, MlpWorkspace& ws) const {
  forwardHidden(X, nullptr, ws);
  outputLayer(ws, Y);
}

void Mlp::calcJacobian(const MatX& X, MatX& Y, MatX& J, MlpWorkspace& ws) const {
  forwardHidden(X, nullptr, ws);
  outputLayer(ws, Y);
  reverse(static_cast<int>(X.cols()), false, J, nullptr, ws);
}

void Mlp::calcJacobianDot(const MatX& X, const MatX& Xdot, MatX& Y, MatX& J, MatX& Jdot, MlpWorkspace& ws) const {
  if (Xdot.rows() != X.rows() || Xdot.cols() != X.cols()) throw std::invalid_argument("Mlp: Xdot must have the shape of X");
  forwardHidden(X, &Xdot, ws);
  outputLayer(ws, Y);
  reverse(static_cast<int>(X.cols()), true, J, &Jdot, ws);
}

void Mlp::calcJacobianDotFd(const MatX& X, const MatX& Xdot, double eps, MatX& Y, MatX& J, MatX& Jdot,
                            MlpWorkspace& ws) const {
  if (Xdot.rows() != X.rows() || Xdot.cols() != X.cols()) throw std::invalid_argument("Mlp: Xdot must have the shape of X");
  // [D Eq. 5.58]: one more Jacobian evaluation at x + eps xdot, forward difference
  MatX Yp, Jp;
  calcJacobian(X + eps * Xdot, Yp, Jp, ws);
  calcJacobian(X, Y, J, ws);
  Jdot = (Jp - J) / eps;
}

bool Mlp::insideBox(const Eigen::Ref<const VecX>& x) const {
  for (int i = 0; i < n_in_; ++i)
    if (!(x[i] >= input_min[i] && x[i] <= input_max[i])) return false;
  return true;
}

std::string Mlp::toText() const {
  std::ostringstream os;
  os << "redmax-mlp 1\n";
  os << "# tanh MLP for Type III wrapping (core/muscles/wrap/network.hpp documents the format)\n";
  os << "inputs " << n_in_ << "\noutputs " << n_out_ << "\nhidden " << hidden_.size();
  for (int h : hidden_) os << ' ' << h;
  os << "\nactivation tanh\n";
  for (const auto& [k, v] : meta) os << "meta " << k << ' ' << v << '\n';
  os << "input_names";
  for (const auto& n : input_names) os << ' ' << n;
  os << "\noutput_names";
  for (const auto& n : output_names) os << ' ' << n;
  os << '\n';
  appendVector(os, "input_mean", input_mean);
  appendVector(os, "input_scale", input_scale);
  appendVector(os, "output_mean", output_mean);
  appendVector(os, "output_scale", output_scale);
  appendVector(os, "input_min", input_min);
  appendVector(os, "input_max", input_max);
  for (std::size_t l = 0; l < W_.size(); ++l) {
    os << "layer " << l << ' ' << W_[l].rows() << ' ' << W_[l].cols() << '\n';
    for (Eigen::Index i = 0; i < W_[l].rows(); ++i) {
      for (Eigen::Index j = 0; j < W_[l].cols(); ++j) os << (j ? " " : "") << fmt17(W_[l](i, j));
      os << '\n';
    }
    for (Eigen::Index i = 0; i < b_[l].size(); ++i) os << (i ? " " : "") << fmt17(b_[l][i]);
    os << '\n';
  }
  os << "end\n";
  return os.str();
}

namespace {

// line reader that skips blank and comment lines and knows its line number
struct LineReader {
  std::istringstream in;
  std::string source;
  int line_no = 0;
  LineReader(const std::string& text, std::string src) : in(text), source(std::move(src)) {}
  [[noreturn]] void fail(const std::string& msg) const {
    throw NetworkFormatError(source + ":" + std::to_string(line_no) + ": " + msg);
  }
  // next non-empty, non-comment line split into words; false at end of input
  bool next(std::vector<std::string>& words, std::string* rest_after_two = nullptr) {
    std::string line;
    while (std::getline(in, line)) {
      ++line_no;
      if (!line.empty() && line.back() == '\r') line.pop_back();
      const auto first = line.find_first_not_of(" \t");
      if (first == std::string::npos || line[first] == '#') continue;
      words.clear();
      std::istringstream ls(line);
      std::string w;
      while (ls >> w) words.push_back(w);
      if (rest_after_two) {
        // the text after the first two words, spaces kept (meta values)
        std::size_t pos = first;
        for (int k = 0; k < 2 && pos != std::string::npos; ++k) {
          pos = line.find_first_of(" \t", pos);
          if (pos != std::string::npos) pos = line.find_first_not_of(" \t", pos);
        }
        *rest_after_two = pos == std::string::npos ? "" : line.substr(pos);
      }
      return true;
    }
    return false;
  }
  std::vector<std::string> expect(const std::string& key) {
    std::vector<std::string> w;
    if (!next(w)) fail("unexpected end of file, expected '" + key + "'");
    if (w[0] != key) fail("expected '" + key + "', found '" + w[0] + "'");
    return w;
  }
  double number(const std::string& s) const {
    char* end = nullptr;
    const double v = std::strtod(s.c_str(), &end);
    if (s.empty() || *end != '\0' || !std::isfinite(v)) fail("'" + s + "' is not a finite number");
    return v;
  }
  int integer(const std::string& s, int lo, int hi) const {
    char* end = nullptr;
    const long v = std::strtol(s.c_str(), &end, 10);
    if (s.empty() || *end != '\0' || v < lo || v > hi)
      fail("'" + s + "' is not an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return static_cast<int>(v);
  }
  VecX vector(const std::vector<std::string>& w, std::size_t first, int n) const {
    if (static_cast<int>(w.size() - first) != n)
      fail("'" + w[0] + "' has " + std::to_string(w.size() - first) + " values, expected " + std::to_string(n));
    VecX v(n);
    for (int i = 0; i < n; ++i) v[i] = number(w[first + i]);
    return v;
  }
};

}  // namespace

Mlp Mlp::fromText(const std::string& text, const std::string& source) {
  LineReader r(text, source);
  std::vector<std::string> w = r.expect("redmax-mlp");
  if (w.size() != 2 || w[1] != "1") r.fail("unsupported format version (this reader knows 'redmax-mlp 1')");
  Mlp m;
  w = r.expect("inputs");
  if (w.size() != 2) r.fail("'inputs' takes one number");
  m.n_in_ = r.integer(w[1], 1, 1000);
  w = r.expect("outputs");
  if (w.size() != 2) r.fail("'outputs' takes one number");
  m.n_out_ = r.integer(w[1], 1, 1000);
  w = r.expect("hidden");
  if (w.size() < 2) r.fail("'hidden' takes a count and the widths");
  const int K = r.integer(w[1], 1, 1000);
  if (static_cast<int>(w.size()) != 2 + K) r.fail("'hidden' declares " + std::to_string(K) + " layers but lists " + std::to_string(w.size() - 2));
  for (int k = 0; k < K; ++k) m.hidden_.push_back(r.integer(w[2 + k], 1, 100000));
  w = r.expect("activation");
  if (w.size() != 2 || w[1] != "tanh") r.fail("only 'activation tanh' is supported");

  // metadata, then the named vectors in fixed order
  std::string rest;
  for (;;) {
    if (!r.next(w, &rest)) r.fail("unexpected end of file, expected 'input_names'");
    if (w[0] != "meta") break;
    if (w.size() < 2) r.fail("'meta' needs a key");
    m.meta[w[1]] = rest;
  }
  if (w[0] != "input_names") r.fail("expected 'input_names', found '" + w[0] + "'");
  m.input_names.assign(w.begin() + 1, w.end());
  if (static_cast<int>(m.input_names.size()) != m.n_in_) r.fail("'input_names' needs " + std::to_string(m.n_in_) + " names");
  w = r.expect("output_names");
  m.output_names.assign(w.begin() + 1, w.end());
  if (static_cast<int>(m.output_names.size()) != m.n_out_) r.fail("'output_names' needs " + std::to_string(m.n_out_) + " names");
  m.input_mean = r.vector(r.expect("input_mean"), 1, m.n_in_);
  m.input_scale = r.vector(r.expect("input_scale"), 1, m.n_in_);
  if ((m.input_scale.array() == 0.0).any()) r.fail("'input_scale' has a zero");
  m.output_mean = r.vector(r.expect("output_mean"), 1, m.n_out_);
  m.output_scale = r.vector(r.expect("output_scale"), 1, m.n_out_);
  m.input_min = r.vector(r.expect("input_min"), 1, m.n_in_);
  m.input_max = r.vector(r.expect("input_max"), 1, m.n_in_);

  std::vector<int> sizes{m.n_in_};
  sizes.insert(sizes.end(), m.hidden_.begin(), m.hidden_.end());
  sizes.push_back(m.n_out_);
  for (int l = 0; l <= K; ++l) {
    w = r.expect("layer");
    if (w.size() != 4) r.fail("'layer' takes index, rows and columns");
    if (r.integer(w[1], 0, K) != l) r.fail("layers must come in order; expected layer " + std::to_string(l));
    const int rows = r.integer(w[2], 1, 100000), cols = r.integer(w[3], 1, 100000);
    if (rows != sizes[l + 1] || cols != sizes[l])
      r.fail("layer " + std::to_string(l) + " is " + w[2] + " x " + w[3] + ", the architecture needs " +
             std::to_string(sizes[l + 1]) + " x " + std::to_string(sizes[l]));
    MatX W(rows, cols);
    std::vector<std::string> row;
    for (int i = 0; i < rows; ++i) {
      if (!r.next(row)) r.fail("unexpected end of file inside layer " + std::to_string(l));
      W.row(i) = r.vector(row, 0, cols).transpose();
    }
    if (!r.next(row)) r.fail("unexpected end of file: missing the biases of layer " + std::to_string(l));
    m.W_.push_back(W);
    m.b_.push_back(r.vector(row, 0, rows));
  }
  w = r.expect("end");
  return m;
}

void Mlp::save(const std::string& path) const {
  // temporary file beside the target, then rename: never a half-written network
  const std::string tmp = path + ".tmp" + std::to_string(std::random_device{}());
  {
    std::ofstream f(tmp, std::ios::binary);
    if (!f) throw std::runtime_error(path + ": cannot write (folder missing or not writable)");
    f << toText();
    f.close();
    if (!f) {
      std::filesystem::remove(tmp);
      throw std::runtime_error(path + ": write failed");
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp);
    throw std::runtime_error(path + ": cannot rename into place: " + ec.message());
  }
}

Mlp Mlp::load(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw std::runtime_error(path + ": cannot open");
  std::ostringstream ss;
  ss << f.rdbuf();
  return fromText(ss.str(), path);
}

bool Mlp::identical(const Mlp& o) const {
  if (n_in_ != o.n_in_ || n_out_ != o.n_out_ || hidden_ != o.hidden_ || W_.size() != o.W_.size()) return false;
  for (std::size_t l = 0; l < W_.size(); ++l)
    if (!bitEqual(W_[l], o.W_[l]) || !bitEqual(b_[l], o.b_[l])) return false;
  return bitEqual(input_mean, o.input_mean) && bitEqual(input_scale, o.input_scale) &&
         bitEqual(output_mean, o.output_mean) && bitEqual(output_scale, o.output_scale) &&
         bitEqual(input_min, o.input_min) && bitEqual(input_max, o.input_max) && input_names == o.input_names &&
         output_names == o.output_names && meta == o.meta;
}

}  // namespace redmax
