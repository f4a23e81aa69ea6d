#include "tools/wrap_training/study.hpp"

namespace redmax {

WrapStudy runWrapThresholdStudy(const WrapStudyOptions& o, const std::function<void(const WrapStudyCurve&)>& on_curve) {
  const WrapType type = WrapType::Cylinder;
  const WrapSurface surf = WrapSurface::makeCylinder(1.0, 1000.0);
  const Vec3 ori(-2.0, 1.2, 0.3);
  const double alpha = 0.5;
  const int n = o.points;
  WrapStudy out;
  out.ins_x.resize(n);
  out.x_exact.resize(n);
  out.dxdins_exact.resize(n);
  auto exactPoint = [&](double x) {
    const Vec3 ins(x, -1.3, -0.2);
    return calcWrappedPathPoint(surf, calcWrap(surf, ori, ins), ori, ins, alpha);
  };
  for (int k = 0; k < n; ++k) {
    out.ins_x[k] = -1.5 + 2.5 * k / (n - 1);
    out.x_exact[k] = exactPoint(out.ins_x[k])[0];
    const double h = 1e-7;  // one-sided near the kink would mix branches: central, tiny step
    out.dxdins_exact[k] = (exactPoint(out.ins_x[k] + h)[0] - exactPoint(out.ins_x[k] - h)[0]) / (2 * h);
  }
  const WrapInputBox box = makeDefaultWrapBox(type);
  const WrapOracle oracle = makeExactWrapOracle(type);
  TrainOptions opt = o.train;
  for (double thr : o.thresholds) {
    const WrapTrainingSet data = makeWrapTrainingSet(box, oracle, o.samples, thr, opt.seed);
    for (const auto& arch : o.architectures) {
      opt.hidden = parseHidden(arch);
      const Mlp net = trainWrapNetwork(data, box, opt);
      MlpWorkspace ws;
      MatX X(8, n), Y, J;
      for (int k = 0; k < n; ++k) X.col(k) << ori, Vec3(out.ins_x[k], -1.3, -0.2), alpha, 1.0;
      net.calcJacobian(X, Y, J, ws);
      WrapStudyCurve c;
      c.threshold = thr;
      c.architecture = arch;
      c.x.resize(n);
      c.dxdins.resize(n);
      for (int k = 0; k < n; ++k) c.x[k] = Y(0, k), c.dxdins[k] = J(0, 8 * k + 3);
      c.val_rms = net.meta.at("final_val_rms_m");
      if (on_curve) on_curve(c);
      out.curves.push_back(std::move(c));
    }
  }
  return out;
}

}  // namespace redmax
