#pragma once
// A fully connected tanh multilayer perceptron for Type III wrapping [D Sec. 5.3.3]: inputs are
// the origin and insertion in the wrap surface's frame S, the arc-length fraction alpha and the
// surface's size parameters; the output is the mass point's position in S [D Eq. 5.38].
//
// Layout. Layer l maps n_l units to n_{l+1}: z = W_l h + b_l, W_l is (n_{l+1} x n_l); hidden
// layers apply tanh, the last layer is linear. Inputs and outputs are normalised with values
// stored beside the weights: u = (x - input_mean) ./ input_scale, y = output_mean + output_scale
// .* v, where v is the raw network output. Batched evaluation takes all points of a muscle as
// the columns of one matrix, so each layer is one matrix-matrix product.
//
// Derivatives. jacobian = d y / d x (n_out x n_in per point) by reverse accumulation through the
// layers [D Eq. 5.44]. jacobianDot = d/dt of the Jacobian along an input velocity xdot, exact:
// the forward tangent of every hidden layer (hdot = (1 - h^2) .* zdot) is carried with the
// reverse pass, using tanh'' = -2 tanh (1 - tanh^2). The dissertation's forward difference of
// Jacobians [D Eq. 5.58] is available as calcJacobianDotFd for comparison.
//
// File format (text, one record per line, '#' starts a comment line; numbers written with 17
// significant digits, which read back bit-exactly):
//   redmax-mlp 1
//   inputs N_IN
//   outputs N_OUT
//   hidden K n_1 ... n_K
//   activation tanh
//   meta KEY VALUE...            (any number; VALUE is the rest of the line)
//   input_names NAME...          (N_IN words)    output_names NAME... (N_OUT words)
//   input_mean V...  input_scale V...  output_mean V...  output_scale V...
//   input_min V...   input_max V...                   (the training box, for runtime checks)
//   layer L ROWS COLS            followed by ROWS lines of COLS weights, then one line of ROWS biases
//   end
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/spatial/types.hpp"

namespace redmax {

/// Error reading a network file: the message starts with "FILE:LINE: ".
struct NetworkFormatError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Scratch buffers of the batched evaluation (sized on first use for a batch size, then reused
/// without allocation for batches of the same size).
struct MlpWorkspace {
  std::vector<MatX> H;     // hidden activations per layer     (n_l x N)
  std::vector<MatX> Hdot;  // their tangents along xdot         (n_l x N)
  MatX U, Udot;            // normalised inputs / velocities    (n_in x N)
  MatX G, A;               // reverse adjoints [G | Gdot]       (n_l x 2 n_out N)
  MatX Jt;                 // input adjoints                    (n_in x 2 n_out N)
};

/// Tanh MLP with stored normalisation, training box and metadata.
class Mlp {
 public:
  Mlp() = default;
  /// Random (Glorot-uniform) weights, zero biases, identity normalisation, box [-1, 1].
  Mlp(int n_in, const std::vector<int>& hidden, int n_out, unsigned long long seed);

  int inputs() const { return n_in_; }
  int outputs() const { return n_out_; }
  const std::vector<int>& hidden() const { return hidden_; }
  int layers() const { return static_cast<int>(W_.size()); }  ///< hidden layers + 1
  long parameterCount() const;
  /// "6x256" style description of the hidden layers
  std::string architecture() const;

  /// Weights of layer l (n_{l+1} x n_l) and biases (n_{l+1}); writable for training.
  MatX& weights(int l) { return W_[l]; }
  VecX& biases(int l) { return b_[l]; }
  const MatX& weights(int l) const { return W_[l]; }
  const VecX& biases(int l) const { return b_[l]; }

  VecX input_mean, input_scale, output_mean, output_scale;  ///< normalisation (see file header)
  VecX input_min, input_max;                                ///< training box, raw input units
  std::vector<std::string> input_names, output_names;
  std::map<std::string, std::string> meta;                  ///< seed, command, surface, loss...

  /// Forward pass. X: n_in x N raw inputs; Y: n_out x N raw outputs.
  void calcOutput(const MatX& X, MatX& Y, MlpWorkspace& ws) const;
  /// Outputs and input Jacobians [D Eq. 5.44]. J: n_out x (n_in N); point p's Jacobian is
  /// J.middleCols(p * n_in, n_in), in raw units (d y / d x).
  void calcJacobian(const MatX& X, MatX& Y, MatX& J, MlpWorkspace& ws) const;
  /// Outputs, Jacobians and their exact time derivatives along input velocities Xdot (n_in x N):
  /// Jdot = sum_i dJ/dx_i xdot_i, same layout as J.
  void calcJacobianDot(const MatX& X, const MatX& Xdot, MatX& Y, MatX& J, MatX& Jdot, MlpWorkspace& ws) const;
  /// The dissertation's forward difference [D Eq. 5.58]: Jdot = (J(x + eps xdot) - J(x)) / eps,
  /// eps a time step in seconds. Same outputs as calcJacobianDot.
  void calcJacobianDotFd(const MatX& X, const MatX& Xdot, double eps, MatX& Y, MatX& J, MatX& Jdot,
                         MlpWorkspace& ws) const;

  /// Whether a raw input lies inside the training box (every component within [min, max]).
  bool insideBox(const Eigen::Ref<const VecX>& x) const;

  /// Serialise to the text format above / parse it (NetworkFormatError naming source and line).
  std::string toText() const;
  static Mlp fromText(const std::string& text, const std::string& source = "<string>");
  /// Write atomically (temporary file + rename) / read. std::runtime_error on I/O failure.
  void save(const std::string& path) const;
  static Mlp load(const std::string& path);

  /// Bitwise equality of everything stored (tests: the serialisation round trip).
  bool identical(const Mlp& other) const;

 private:
  // hidden pass: fills ws.U and ws.H (and ws.Udot, ws.Hdot when Xdot is given)
  void forwardHidden(const MatX& X, const MatX* Xdot, MlpWorkspace& ws) const;
  // output layer from ws.H.back()
  void outputLayer(const MlpWorkspace& ws, MatX& Y) const;
  // reverse pass: input Jacobians (and their derivatives when with_dot) into J (and Jdot)
  void reverse(int N, bool with_dot, MatX& J, MatX* Jdot, MlpWorkspace& ws) const;

  int n_in_ = 0, n_out_ = 0;
  std::vector<int> hidden_;
  std::vector<MatX> W_;
  std::vector<VecX> b_;
};

}  // namespace redmax
