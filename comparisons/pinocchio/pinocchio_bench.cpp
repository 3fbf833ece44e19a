// Times Pinocchio's dynamics algorithms on a fixed-base URDF robot, for the
// side-by-side comparison with appell's generated code (see README.md here).
//
//   pinocchio_bench URDF [--name NAME] [--weld J1,J2,...] [--batch B]
//                        [--reps R] [--seed S] [--only aba,rnea,...]
//   pinocchio_bench URDF [--weld ...] --check   < states   (see check())
//
// The batch of states is drawn from SplitMix64 exactly as the Rust driver
// (rust/src/main.rs) draws it, in Pinocchio's joint order: for each state,
// q_i uniform in [-pi, pi), then v_i, then tau_i uniform in [-1, 1). RNEA
// takes the tau vector as its acceleration a. Gravity is Pinocchio's
// default, (0, 0, -9.81).
//
// Output: JSON lines. First one describing the model (joint names in
// Pinocchio's order), then one per timed function: the per-call time in ns
// of each repetition (one pass over the whole batch) summarised as median,
// min and max over the repetitions, and a checksum (the sum of every output
// entry over the batch, from an untimed pass) to compare with the other
// implementations.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <pinocchio/algorithm/aba.hpp>
#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/joint-configuration.hpp>
#include <pinocchio/algorithm/model.hpp>
#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/multibody.hpp>
#include <pinocchio/parsers/urdf.hpp>

namespace
{

  // SplitMix64; uniform() takes the top 53 bits, in [0, 1). The Rust driver
  // has the same generator.
  struct SplitMix64
  {
    uint64_t state;
    uint64_t next()
    {
      uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
      z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
      z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
      return z ^ (z >> 31);
    }
    double uniform(double lo, double hi)
    {
      double u = static_cast<double>(next() >> 11) * 0x1.0p-53;
      return lo + (hi - lo) * u;
    }
  };

  std::vector<std::string> split(const std::string & s, char sep)
  {
    std::vector<std::string> out;
    std::stringstream in(s);
    std::string item;
    while (std::getline(in, item, sep))
      if (!item.empty())
        out.push_back(item);
    return out;
  }

  [[noreturn]] void usage(const char * why)
  {
    std::fprintf(stderr, "pinocchio_bench: %s\n", why);
    std::fprintf(
      stderr, "usage: pinocchio_bench URDF [--name NAME] [--weld J1,J2] [--batch B] [--reps R] "
              "[--seed S] [--only F1,F2] [--check]\n");
    std::exit(2);
  }

  std::string json_string(const std::string & s)
  {
    std::string out = "\"";
    for (char c : s)
    {
      if (c == '"' || c == '\\')
        out += '\\';
      out += c;
    }
    return out + "\"";
  }

  // Loads the URDF with a fixed base and welds the joints `weld` at 0, as
  // tests/reference/pinocchio/make_reference.py does (buildReducedModel at
  // the neutral configuration with those joints' entries set to 0).
  pinocchio::Model load(const std::string & urdf, const std::vector<std::string> & weld)
  {
    pinocchio::Model full;
    pinocchio::urdf::buildModel(urdf, full);
    if (weld.empty())
      return full;
    std::vector<pinocchio::JointIndex> ids;
    Eigen::VectorXd q_ref = pinocchio::neutral(full);
    for (const std::string & name : weld)
    {
      if (!full.existJointName(name))
        usage(("no joint named " + name).c_str());
      pinocchio::JointIndex id = full.getJointId(name);
      if (full.joints[id].nq() != 1)
        usage(("welded joint " + name + " is not a one-coordinate joint").c_str());
      q_ref[full.joints[id].idx_q()] = 0.0;
      ids.push_back(id);
    }
    pinocchio::Model reduced;
    pinocchio::buildReducedModel(full, ids, q_ref, reduced);
    return reduced;
  }

  // --check: reads whitespace-separated states from stdin, each q (nv), v,
  // tau, a, and prints per state one JSON line with aba(q, v, tau),
  // rnea(q, v, a), the symmetric crba(q) row-major, nonLinearEffects(q, v)
  // and computeGeneralizedGravity(q), at full precision. run.py compares
  // them with tests/reference/pinocchio/*.json.
  int check(const pinocchio::Model & model)
  {
    pinocchio::Data data(model);
    const int n = model.nv;
    Eigen::VectorXd q(n), v(n), tau(n), a(n);
    auto read = [&](Eigen::VectorXd & x) {
      for (int i = 0; i < n; ++i)
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

  struct Batch
  {
    int n, count;
    std::vector<Eigen::VectorXd> q, v, tau;
  };

  Batch draw(int n, int count, uint64_t seed)
  {
    SplitMix64 rng{seed};
    Batch b{n, count, {}, {}, {}};
    const double pi = 3.14159265358979323846;
    for (int k = 0; k < count; ++k)
    {
      Eigen::VectorXd q(n), v(n), tau(n);
      for (int i = 0; i < n; ++i)
        q[i] = rng.uniform(-pi, pi);
      for (int i = 0; i < n; ++i)
        v[i] = rng.uniform(-1.0, 1.0);
      for (int i = 0; i < n; ++i)
        tau[i] = rng.uniform(-1.0, 1.0);
      b.q.push_back(q);
      b.v.push_back(v);
      b.tau.push_back(tau);
    }
    return b;
  }

  volatile double sink;

  // Times one function: `call(k)` evaluates state k and returns the first
  // entry of its result (accumulated, so that nothing can be dropped);
  // `sum(k)` evaluates state k again and returns the sum of all the entries
  // of its result, for the checksum. Templates, so that the calls inline
  // as in a user's loop (no indirect call per evaluation).
  template<typename Call, typename Sum>
  void time_function(
    const std::string & model_name,
    const char * fn,
    Call call,
    Sum sum,
    int count,
    int reps,
    const char * build)
  {
    using clock = std::chrono::steady_clock;
    double acc = 0.0;
    for (int k = 0; k < count; ++k) // warm-up pass
      acc += call(k);
    std::vector<double> per_call(reps);
    for (int r = 0; r < reps; ++r)
    {
      auto start = clock::now();
      for (int k = 0; k < count; ++k)
        acc += call(k);
      auto stop = clock::now();
      per_call[r] = std::chrono::duration<double, std::nano>(stop - start).count() / count;
    }
    sink = acc;
    double checksum = 0.0;
    for (int k = 0; k < count; ++k)
      checksum += sum(k);
    std::vector<double> sorted = per_call;
    std::sort(sorted.begin(), sorted.end());
    double median = reps % 2 ? sorted[reps / 2] : 0.5 * (sorted[reps / 2 - 1] + sorted[reps / 2]);
    std::printf(
      "{\"impl\":\"pinocchio\",\"build\":%s,\"model\":%s,\"fn\":\"%s\",\"batch\":%d,\"reps\":%d,"
      "\"median_ns\":%.2f,\"min_ns\":%.2f,\"max_ns\":%.2f,\"checksum\":%.17g}\n",
      json_string(build).c_str(), json_string(model_name).c_str(), fn, count, reps, median,
      sorted.front(), sorted.back(), checksum);
    std::fflush(stdout);
  }

} // namespace

int main(int argc, char ** argv)
{
  if (argc < 2)
    usage("no URDF given");
  std::string urdf = argv[1], name;
  std::vector<std::string> weld, only;
  int count = 1000, reps = 31;
  uint64_t seed = 20240917;
  bool check_mode = false;
  for (int i = 2; i < argc; ++i)
  {
    std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc)
        usage((arg + " needs a value").c_str());
      return argv[++i];
    };
    if (arg == "--name")
      name = value();
    else if (arg == "--weld")
      weld = split(value(), ',');
    else if (arg == "--batch")
      count = std::atoi(value().c_str());
    else if (arg == "--reps")
      reps = std::atoi(value().c_str());
    else if (arg == "--seed")
      seed = std::strtoull(value().c_str(), nullptr, 10);
    else if (arg == "--only")
      only = split(value(), ',');
    else if (arg == "--check")
      check_mode = true;
    else
      usage(("unknown argument " + arg).c_str());
  }
  if (count < 1 || reps < 1)
    usage("--batch and --reps must be positive");
  if (name.empty())
    name = urdf;

  pinocchio::Model model = load(urdf, weld);
  const int n = model.nv;
  if (model.nq != n)
    usage("the model has joints whose nq differs from nv");
  for (pinocchio::JointIndex j = 1; j < (pinocchio::JointIndex)model.njoints; ++j)
  {
    const std::string kind = model.joints[j].shortname();
    if (kind.rfind("JointModelR", 0) != 0 || model.joints[j].nq() != 1)
      usage(("joint " + model.names[j] + " is not revolute (" + kind + ")").c_str());
  }
  if (check_mode)
    return check(model);

#ifdef PINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION
  const char * build = "pinocchio's precompiled library (PINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION)";
#else
  const char * build = "header-only, this compiler's flags";
#endif

  std::printf(
    "{\"impl\":\"pinocchio\",\"version\":\"%s\",\"build\":%s,\"model\":%s,\"nv\":%d,\"joints\":[",
    PINOCCHIO_VERSION, json_string(build).c_str(), json_string(name).c_str(), n);
  for (int j = 1; j < model.njoints; ++j)
    std::printf("%s%s", j > 1 ? "," : "", json_string(model.names[j]).c_str());
  std::printf("],\"gravity\":[%g,%g,%g]}\n", model.gravity.linear()[0],
              model.gravity.linear()[1], model.gravity.linear()[2]);

  pinocchio::Data data(model);
  Batch b = draw(n, count, seed);
  Eigen::VectorXd f(n);

  auto symmetrize = [&]() {
    data.M.triangularView<Eigen::StrictlyLower>() =
      data.M.transpose().triangularView<Eigen::StrictlyLower>();
  };
  const std::vector<std::string> names = {"aba",      "rnea", "crba",    "crba_sym",
                                          "nle",      "gravity", "crba_nle"};
  for (const std::string & want : only)
    if (std::find(names.begin(), names.end(), want) == names.end())
      usage(("unknown function " + want).c_str());
  auto wanted = [&](const char * fn) {
    return only.empty() || std::find(only.begin(), only.end(), fn) != only.end();
  };
  auto run = [&](const char * fn, auto call, auto sum) {
    if (wanted(fn))
      time_function(name, fn, call, sum, count, reps, build);
  };

  run(
    "aba", [&](int k) { return pinocchio::aba(model, data, b.q[k], b.v[k], b.tau[k])[0]; },
    [&](int k) { return pinocchio::aba(model, data, b.q[k], b.v[k], b.tau[k]).sum(); });
  run(
    "rnea", [&](int k) { return pinocchio::rnea(model, data, b.q[k], b.v[k], b.tau[k])[0]; },
    [&](int k) { return pinocchio::rnea(model, data, b.q[k], b.v[k], b.tau[k]).sum(); });
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
  return 0;
}
