// Times Pinocchio's dynamics algorithms on a URDF robot, with a fixed base
// or (--free) on a JointModelFreeFlyer, for the side-by-side comparison
// with appell's generated code (see README.md here).
//
//   pinocchio_bench URDF [--free] [--name NAME] [--weld J1,J2,...] [--batch B]
//                        [--reps R] [--seed S] [--only aba,rnea,...]
//   pinocchio_bench URDF [--free] [--weld ...] --check   < states   (see check())
//   pinocchio_bench URDF [--weld ...] [--batch B] --dump-derivatives   (see dump())
//
// The batch of states is drawn from SplitMix64 exactly as the Rust driver
// (rust/src/main.rs) draws it, in Pinocchio's joint order (bench::draw in
// bench_common.hpp says how; for a fixed base: q_i uniform in [-pi, pi),
// then v_i, then tau_i uniform in [-1, 1)). RNEA takes the drawn tau
// vector (before a free base's entries are zeroed) as its acceleration a.
// Gravity is Pinocchio's default, (0, 0, -9.81).
//
// Output: JSON lines. First one describing the model (joint names in
// Pinocchio's order), then one per timed function: the per-call time in ns
// of each repetition (one pass over the whole batch) summarised as median,
// min and max over the repetitions, and a checksum (the sum of every output
// entry over the batch, from an untimed pass) to compare with the other
// implementations.
//
// aba_derivatives is computeABADerivatives(model, data, q, v, tau): the
// partial derivatives of the accelerations data.ddq_dq (nv x nq),
// data.ddq_dv (nv x nv) and data.Minv (= d ddq / d tau). Its documentation
// (algorithm/aba-derivatives.hpp) says that, as for computeMinverse, only
// the upper triangle of data.Minv is filled (Pinocchio 4.1's implementation
// happens to copy it into the lower one before forming ddq_dq and ddq_dv,
// but that is not promised), so the checksum reads the upper triangle only:
// sum(ddq_dq) + sum(ddq_dv) + (2 sum(upper triangle of Minv) - trace(Minv)),
// the sum of every entry of the symmetric M^-1.

#include <iostream>

#include <pinocchio/algorithm/aba-derivatives.hpp>
#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/joint-configuration.hpp>
#include <pinocchio/algorithm/model.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/multibody.hpp>
#include <pinocchio/parsers/urdf.hpp>

#include "bench_common.hpp"

namespace
{

  // --check: reads whitespace-separated states from stdin, each q (nq), v
  // (nv), tau, a, and prints per state one JSON line with aba(q, v, tau),
  // rnea(q, v, a), the symmetric crba(q) row-major, nonLinearEffects(q, v)
  // and computeGeneralizedGravity(q), at full precision. run.py compares
  // them with tests/reference/pinocchio/*.json.
  int check(const pinocchio::Model & model)
  {
    pinocchio::Data data(model);
    const int n = model.nv;
    Eigen::VectorXd q(model.nq), v(n), tau(n), a(n);
    auto read = [&](Eigen::VectorXd & x) {
      for (Eigen::Index i = 0; i < x.size(); ++i)
        if (!(std::cin >> x[i]))
          return false;
      return true;
    };
    auto list = [](const Eigen::VectorXd & x) {
      std::string s = "[";
      char buf[32];
      for (Eigen::Index i = 0; i < x.size(); ++i)
      {
        std::snprintf(buf, sizeof buf, "%.17g", x[i]);
        s += (i ? "," : "");
        s += buf;
      }
      return s + "]";
    };
    while (read(q) && read(v) && read(tau) && read(a))
    {
      Eigen::VectorXd ddq = pinocchio::aba(model, data, q, v, tau);
      Eigen::VectorXd rnea = pinocchio::rnea(model, data, q, v, a);
      pinocchio::crba(model, data, q);
      data.M.triangularView<Eigen::StrictlyLower>() =
        data.M.transpose().triangularView<Eigen::StrictlyLower>();
      Eigen::MatrixXd mt = data.M.transpose();
      Eigen::VectorXd mass = Eigen::Map<Eigen::VectorXd>(mt.data(), n * n);
      Eigen::VectorXd nle = pinocchio::nonLinearEffects(model, data, q, v);
      Eigen::VectorXd grav = pinocchio::computeGeneralizedGravity(model, data, q);
      std::printf(
        "{\"ddq\":%s,\"rnea\":%s,\"mass_matrix\":%s,\"nle\":%s,\"gravity_torque\":%s}\n",
        list(ddq).c_str(), list(rnea).c_str(), list(mass).c_str(), list(nle).c_str(),
        list(grav).c_str());
    }
    return 0;
  }

  // The sum of every entry of data.Minv as a symmetric matrix, from its
  // upper triangle (the part computeABADerivatives is documented to fill).
  double minv_sum(const pinocchio::Data & data)
  {
    const auto upper = data.Minv.triangularView<Eigen::Upper>().toDenseMatrix();
    return 2.0 * upper.sum() - data.Minv.diagonal().sum();
  }

  // --dump-derivatives: for each state of the batch, one JSON line with
  // computeABADerivatives' ddq, ddq_dq, ddq_dv and ddq_dtau (Minv, its
  // lower triangle taken from the upper one), rows and columns in
  // Pinocchio's joint order. run.py compares them entry by entry with
  // appell_bench --dump-jacobian's.
  int dump(const pinocchio::Model & model, const bench::Batch & b, const std::string & name)
  {
    pinocchio::Data data(model);
    auto number = [](double x) {
      char buf[32];
      std::snprintf(buf, sizeof buf, "%.17g", x);
      return std::string(buf);
    };
    auto list = [&](const Eigen::VectorXd & x) {
      std::string s = "[";
      for (Eigen::Index i = 0; i < x.size(); ++i)
        s += (i ? "," : "") + number(x[i]);
      return s + "]";
    };
    auto matrix = [&](const Eigen::MatrixXd & m) {
      std::string s = "[";
      for (Eigen::Index i = 0; i < m.rows(); ++i)
      {
        s += i ? ",[" : "[";
        for (Eigen::Index j = 0; j < m.cols(); ++j)
          s += (j ? "," : "") + number(m(i, j));
        s += "]";
      }
      return s + "]";
    };
    for (int k = 0; k < b.count; ++k)
    {
      pinocchio::computeABADerivatives(model, data, b.q[k], b.v[k], b.tau[k]);
      Eigen::MatrixXd minv = data.Minv.triangularView<Eigen::Upper>();
      minv.triangularView<Eigen::StrictlyLower>() =
        minv.transpose().triangularView<Eigen::StrictlyLower>();
      std::printf(
        "{\"model\":%s,\"state\":%d,\"ddq\":%s,\"ddq_dq\":%s,\"ddq_dv\":%s,\"ddq_dtau\":%s}\n",
        bench::json_string(name).c_str(), k, list(data.ddq).c_str(),
        matrix(data.ddq_dq).c_str(), matrix(data.ddq_dv).c_str(), matrix(minv).c_str());
    }
    return 0;
  }

} // namespace

int main(int argc, char ** argv)
{
  bool dump_derivatives = false;
  const bench::Options o = bench::parse(argc, argv, [&](const std::string & arg, auto &&) {
    if (arg != "--dump-derivatives")
      return false;
    dump_derivatives = true;
    return true;
  });
  const pinocchio::Model model = bench::load(o);
  const int n = model.nv;
  if (o.check)
    return check(model);
  if (dump_derivatives)
    return dump(model, bench::draw(model, o.free, o.count, o.seed), o.name);

#ifdef PINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION
  const char * build = "pinocchio's precompiled library (PINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION)";
#else
  const char * build = "header-only, this compiler's flags";
#endif
  bench::print_head(model, o, "pinocchio", build);

  pinocchio::Data data(model);
  const bench::Batch b = bench::draw(model, o.free, o.count, o.seed);
  Eigen::VectorXd f(n);

  auto symmetrize = [&]() {
    data.M.triangularView<Eigen::StrictlyLower>() =
      data.M.transpose().triangularView<Eigen::StrictlyLower>();
  };
  const std::vector<std::string> names = {"aba",      "rnea", "crba",    "crba_sym",
                                          "nle",      "gravity", "crba_nle", "aba_derivatives"};
  auto run = [&](const char * fn, auto call, auto sum) {
    if (bench::wanted(o.only, names, fn))
      bench::time_function("pinocchio", o.name, fn, call, sum, o.count, o.reps, build);
  };

  run(
    "aba", [&](int k) { return pinocchio::aba(model, data, b.q[k], b.v[k], b.tau[k])[0]; },
    [&](int k) { return pinocchio::aba(model, data, b.q[k], b.v[k], b.tau[k]).sum(); });
  run(
    "rnea", [&](int k) { return pinocchio::rnea(model, data, b.q[k], b.v[k], b.a[k])[0]; },
    [&](int k) { return pinocchio::rnea(model, data, b.q[k], b.v[k], b.a[k]).sum(); });
  // crba fills the upper triangle only (its documentation says so); the
  // checksum sums that triangle.
  run(
    "crba", [&](int k) { return pinocchio::crba(model, data, b.q[k])(0, n - 1); },
    [&](int k) {
      pinocchio::crba(model, data, b.q[k]);
      return data.M.triangularView<Eigen::Upper>().toDenseMatrix().sum();
    });
  // crba, then the strictly lower triangle copied from the upper one, as a
  // user who needs the whole matrix does.
  run(
    "crba_sym",
    [&](int k) {
      pinocchio::crba(model, data, b.q[k]);
      symmetrize();
      return data.M(n - 1, 0);
    },
    [&](int k) {
      pinocchio::crba(model, data, b.q[k]);
      symmetrize();
      return data.M.sum();
    });
  run(
    "nle", [&](int k) { return pinocchio::nonLinearEffects(model, data, b.q[k], b.v[k])[0]; },
    [&](int k) { return pinocchio::nonLinearEffects(model, data, b.q[k], b.v[k]).sum(); });
  run(
    "gravity", [&](int k) { return pinocchio::computeGeneralizedGravity(model, data, b.q[k])[0]; },
    [&](int k) { return pinocchio::computeGeneralizedGravity(model, data, b.q[k]).sum(); });
  // The counterpart of appell's mass_matrix_and_forcing: the whole mass
  // matrix M and the forcing f = tau - nle of M ddq = f.
  run(
    "crba_nle",
    [&](int k) {
      pinocchio::crba(model, data, b.q[k]);
      symmetrize();
      f.noalias() = b.tau[k] - pinocchio::nonLinearEffects(model, data, b.q[k], b.v[k]);
      return data.M(n - 1, 0) + f[0];
    },
    [&](int k) {
      pinocchio::crba(model, data, b.q[k]);
      symmetrize();
      f.noalias() = b.tau[k] - pinocchio::nonLinearEffects(model, data, b.q[k], b.v[k]);
      return data.M.sum() + f.sum();
    });
  // The derivatives of forward dynamics (the counterpart of appell's
  // rhs_jacobian); the checksum as the header comment says.
  run(
    "aba_derivatives",
    [&](int k) {
      pinocchio::computeABADerivatives(model, data, b.q[k], b.v[k], b.tau[k]);
      return data.ddq_dv(n - 1, n - 1);
    },
    [&](int k) {
      pinocchio::computeABADerivatives(model, data, b.q[k], b.v[k], b.tau[k]);
      return data.ddq_dq.sum() + data.ddq_dv.sum() + minv_sum(data);
    });
  return 0;
}
