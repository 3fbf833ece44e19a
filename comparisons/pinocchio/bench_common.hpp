// What pinocchio_bench.cpp and pinocchio_cg_bench.cpp share: the command
// line, loading the URDF (fixed or free base), the random batch of states
// (drawn as rust/src/main.rs draws it), and the timing loop. Include it
// after Pinocchio's headers (the code-generation driver must include
// pinocchio/codegen/cppadcg.hpp before any other Pinocchio header).

#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include <pinocchio/algorithm/joint-configuration.hpp>
#include <pinocchio/algorithm/model.hpp>
#include <pinocchio/multibody.hpp>
#include <pinocchio/parsers/urdf.hpp>

namespace bench
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

  inline std::vector<std::string> split(const std::string & s, char sep)
  {
    std::vector<std::string> out;
    std::stringstream in(s);
    std::string item;
    while (std::getline(in, item, sep))
      if (!item.empty())
        out.push_back(item);
    return out;
  }

  inline const char * program = "pinocchio_bench";

  [[noreturn]] inline void usage(const char * why)
  {
    std::fprintf(stderr, "%s: %s\n", program, why);
    std::fprintf(
      stderr,
      "usage: %s URDF [--free] [--name NAME] [--weld J1,J2] [--batch B] [--reps R] "
      "[--seed S] [--only F1,F2] [--check]\n",
      program);
    std::exit(2);
  }

  inline std::string json_string(const std::string & s)
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

  // The command line both drivers take (the code-generation one adds its
  // own options through `extra`).
  struct Options
  {
    std::string urdf, name;
    std::vector<std::string> weld, only;
    int count = 1000, reps = 31;
    uint64_t seed = 20240917;
    bool check = false, free = false;
  };

  template<typename Extra>
  Options parse(int argc, char ** argv, Extra extra)
  {
    if (argc < 2)
      usage("no URDF given");
    Options o;
    o.urdf = argv[1];
    for (int i = 2; i < argc; ++i)
    {
      std::string arg = argv[i];
      auto value = [&]() -> std::string {
        if (i + 1 >= argc)
          usage((arg + " needs a value").c_str());
        return argv[++i];
      };
      if (arg == "--name")
        o.name = value();
      else if (arg == "--weld")
        o.weld = split(value(), ',');
      else if (arg == "--batch")
        o.count = std::atoi(value().c_str());
      else if (arg == "--reps")
        o.reps = std::atoi(value().c_str());
      else if (arg == "--seed")
        o.seed = std::strtoull(value().c_str(), nullptr, 10);
      else if (arg == "--only")
        o.only = split(value(), ',');
      else if (arg == "--check")
        o.check = true;
      else if (arg == "--free")
        o.free = true;
      else if (!extra(arg, value))
        usage(("unknown argument " + arg).c_str());
    }
    if (o.count < 1 || o.reps < 1)
      usage("--batch and --reps must be positive");
    if (o.name.empty())
      o.name = o.urdf;
    return o;
  }

  // Loads the URDF, with a fixed base or (`free`) on a
  // JointModelFreeFlyer named `root_joint`, and welds the joints `weld` at
  // 0, as tests/reference/pinocchio/make_reference.py does
  // (buildReducedModel at the neutral configuration with those joints'
  // entries set to 0). Every other joint must be a one-coordinate revolute
  // joint.
  inline pinocchio::Model load(const Options & o)
  {
    pinocchio::Model full;
    if (o.free)
      pinocchio::urdf::buildModel(o.urdf, pinocchio::JointModelFreeFlyer(), full);
    else
      pinocchio::urdf::buildModel(o.urdf, full);
    pinocchio::Model model;
    if (o.weld.empty())
      model = full;
    else
    {
      std::vector<pinocchio::JointIndex> ids;
      Eigen::VectorXd q_ref = pinocchio::neutral(full);
      for (const std::string & name : o.weld)
      {
        if (!full.existJointName(name))
          usage(("no joint named " + name).c_str());
        pinocchio::JointIndex id = full.getJointId(name);
        if (full.joints[id].nq() != 1)
          usage(("welded joint " + name + " is not a one-coordinate joint").c_str());
        q_ref[full.joints[id].idx_q()] = 0.0;
        ids.push_back(id);
      }
      pinocchio::buildReducedModel(full, ids, q_ref, model);
    }
    for (pinocchio::JointIndex j = 1; j < (pinocchio::JointIndex)model.njoints; ++j)
    {
      const std::string kind = model.joints[j].shortname();
      if (o.free && j == 1)
      {
        if (kind != "JointModelFreeFlyer")
          usage(("the first joint is " + kind + ", not the free flyer").c_str());
        continue;
      }
      if (kind.rfind("JointModelR", 0) != 0 || model.joints[j].nq() != 1)
        usage(("joint " + model.names[j] + " is not revolute (" + kind + ")").c_str());
    }
    return model;
  }

  // The batch of states. For each state, in Pinocchio's order:
  // - q: with a free base, its position (3 values uniform in [-1, 1)) and
  //   its quaternion (x, y, z, w: 4 values uniform in [-1, 1), divided by
  //   their norm); then each joint's angle uniform in [-pi, pi);
  // - v: nv values uniform in [-1, 1) (a free base's linear then angular
  //   velocity in its own axes, then the joints');
  // - w: nv values uniform in [-1, 1). RNEA's acceleration `a` is w; ABA's
  //   torque `tau` is w with the free base's six entries set to 0 (the base
  //   is not actuated; appell's URDF models have inputs at the joints only).
  // A fixed-base model draws q, v, tau per joint exactly as before the free
  // base was added (a = tau).
  struct Batch
  {
    int nq, nv, count;
    std::vector<Eigen::VectorXd> q, v, tau, a;
  };

  inline Batch draw(const pinocchio::Model & model, bool free, int count, uint64_t seed)
  {
    SplitMix64 rng{seed};
    const int nq = model.nq, nv = model.nv, base_q = free ? 7 : 0, base_v = free ? 6 : 0;
    Batch b{nq, nv, count, {}, {}, {}, {}};
    const double pi = 3.14159265358979323846;
    for (int k = 0; k < count; ++k)
    {
      Eigen::VectorXd q(nq), v(nv), tau(nv), a(nv);
      if (free)
      {
        for (int i = 0; i < 7; ++i)
          q[i] = rng.uniform(-1.0, 1.0);
        double norm = std::sqrt(q[3] * q[3] + q[4] * q[4] + q[5] * q[5] + q[6] * q[6]);
        for (int i = 3; i < 7; ++i)
          q[i] /= norm;
      }
      for (int i = base_q; i < nq; ++i)
        q[i] = rng.uniform(-pi, pi);
      for (int i = 0; i < nv; ++i)
        v[i] = rng.uniform(-1.0, 1.0);
      for (int i = 0; i < nv; ++i)
        a[i] = rng.uniform(-1.0, 1.0);
      tau = a;
      tau.head(base_v).setZero();
      b.q.push_back(q);
      b.v.push_back(v);
      b.tau.push_back(tau);
      b.a.push_back(a);
    }
    return b;
  }

  // The JSON line describing the model: joint names in Pinocchio's order
  // (the free flyer's `root_joint` first).
  inline void print_head(
    const pinocchio::Model & model, const Options & o, const char * impl, const char * build)
  {
    std::printf(
      "{\"impl\":\"%s\",\"version\":\"%s\",\"build\":%s,\"model\":%s,\"nq\":%d,\"nv\":%d,"
      "\"free\":%s,\"joints\":[",
      impl, PINOCCHIO_VERSION, json_string(build).c_str(), json_string(o.name).c_str(), model.nq,
      model.nv, o.free ? "true" : "false");
    for (int j = 1; j < model.njoints; ++j)
      std::printf("%s%s", j > 1 ? "," : "", json_string(model.names[j]).c_str());
    std::printf(
      "],\"gravity\":[%g,%g,%g]}\n", model.gravity.linear()[0], model.gravity.linear()[1],
      model.gravity.linear()[2]);
  }

  inline volatile double sink;

  // Times one function: `call(k)` evaluates state k and returns the first
  // entry of its result (accumulated, so that nothing can be dropped);
  // `sum(k)` evaluates state k again and returns the sum of all the entries
  // of its result, for the checksum. Templates, so that the calls inline
  // as in a user's loop (no indirect call per evaluation).
  template<typename Call, typename Sum>
  void time_function(
    const char * impl,
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
      "{\"impl\":\"%s\",\"build\":%s,\"model\":%s,\"fn\":\"%s\",\"batch\":%d,\"reps\":%d,"
      "\"median_ns\":%.2f,\"min_ns\":%.2f,\"max_ns\":%.2f,\"checksum\":%.17g}\n",
      impl, json_string(build).c_str(), json_string(model_name).c_str(), fn, count, reps, median,
      sorted.front(), sorted.back(), checksum);
    std::fflush(stdout);
  }

  // Whether `fn` is among `only` (all when `only` is empty), after checking
  // that every name in `only` is one of `names`.
  inline bool wanted(
    const std::vector<std::string> & only, const std::vector<std::string> & names, const char * fn)
  {
    for (const std::string & want : only)
      if (std::find(names.begin(), names.end(), want) == names.end())
        usage(("unknown function " + want).c_str());
    return only.empty() || std::find(only.begin(), only.end(), fn) != only.end();
  }

} // namespace bench
