// Times Pinocchio's code-generated dynamics (CppADCodeGen): CodeGenABA,
// CodeGenRNEA, CodeGenCRBA, CodeGenABADerivatives (computeABADerivatives
// recorded), and a gravity generator written here on Pinocchio's
// CodeGenBase as its own generators are, on the same states as
// pinocchio_bench (bench_common.hpp draws them).
//
//   pinocchio_cg_bench URDF [--free] [--name NAME] [--weld J1,J2,...] [--batch B] [--reps R]
//                           [--seed S] [--only aba,rnea,crba_sym,gravity,aba_derivatives]
//                           [--cflags "-Ofast -march=native"]
//
// Each function is recorded with CppAD on Pinocchio's algorithm (scalar
// CppAD::AD<CppAD::cg::CG<double>>), turned into C by CppADCodeGen, and
// compiled by gcc into a shared library `NAME_FN_<robot>.so` in the
// current directory (run.py runs this in build/cg) unless that file is
// already there; then loaded with dlopen and called through the
// generators' evalFunction, as Pinocchio's own benchmark does. The
// generated C is compiled with --cflags (default "-Ofast -march=native":
// Pinocchio's default -Ofast for its generated code, and this CPU's
// instructions as for every other native build here). Only forward
// evaluation is generated (no Jacobians of the recorded functions: the
// derivatives timed are computeABADerivatives' own, recorded as a
// function of q, v and tau).
//
// Output: as pinocchio_bench's (impl "pinocchio_cg"), plus one line per
// function saying how long recording, generating and compiling took.

// CppADCodeGen's scalar traits must come before any other Pinocchio header.
#include <pinocchio/codegen/cppadcg.hpp>

#include <pinocchio/codegen/cppadcg-algo.hpp>

#include <pinocchio/algorithm/rnea.hpp>
#include <pinocchio/parsers/urdf.hpp>

#include "bench_common.hpp"

namespace
{

  // The generalized gravity g(q) (computeGeneralizedGravity), generated as
  // Pinocchio's generators do theirs: input q, output the nv entries of g.
  struct CodeGenGravity : public pinocchio::CodeGenBase<double>
  {
    typedef pinocchio::CodeGenBase<double> Base;

    CodeGenGravity(
      const Model & model, const std::string & function_name, const std::string & library_name)
    : Base(model, model.nq, model.nv, function_name, library_name)
    {
      ad_q = pinocchio::neutral(ad_model);
      x = VectorXs::Zero(model.nq);
      build_jacobian = false;
    }

    void buildMap() override
    {
      CppAD::Independent(ad_X);
      ad_q = ad_X.segment(0, ad_model.nq);
      pinocchio::computeGeneralizedGravity(ad_model, ad_data, ad_q);
      ad_Y = ad_data.g;
      ad_fun.Dependent(ad_X, ad_Y);
      ad_fun.optimize("no_compare_op");
    }

    template<typename ConfigVectorType>
    void evalFunction(const Eigen::MatrixBase<ConfigVectorType> & q)
    {
      x = q;
      Base::evalFunction(x);
    }

    VectorXs x;
    ADConfigVectorType ad_q;
  };

  // A generator with its output and compilation opened up: `out()` is the
  // last evaluation's result (the generators keep it in protected members),
  // `prepare` records, generates and compiles (unless the library exists)
  // with the given gcc flags, then loads.
  template<typename Generator>
  struct Opened : public Generator
  {
    using Generator::Generator;

    const Eigen::VectorXd & out() const
    {
      return this->y;
    }

    // Seconds spent; whether the library had to be compiled.
    std::pair<double, bool> prepare(const std::vector<std::string> & cflags)
    {
      auto start = std::chrono::steady_clock::now();
      this->build_jacobian = false;
      this->initLib();
      const bool compile = !this->existLib();
      if (compile)
      {
        CppAD::cg::GccCompiler<double> gcc("/usr/bin/gcc");
        gcc.setCompileFlags(cflags);
        this->dynamicLibManager_ptr->createDynamicLibrary(gcc, false);
      }
      this->loadLib(false);
      auto stop = std::chrono::steady_clock::now();
      return {std::chrono::duration<double>(stop - start).count(), compile};
    }
  };

} // namespace

int main(int argc, char ** argv)
{
  bench::program = "pinocchio_cg_bench";
  std::string cflags = "-Ofast -march=native";
  const bench::Options o = bench::parse(argc, argv, [&](const std::string & arg, auto && value) {
    if (arg != "--cflags")
      return false;
    cflags = value();
    return true;
  });
  if (o.check)
    bench::usage("--check is pinocchio_bench's");
  const pinocchio::Model model = bench::load(o);
  const int n = model.nv;
  const std::string build = "CppADCodeGen " + std::string(CPPAD_PACKAGE_STRING)
                            + ", generated C compiled by gcc " + cflags;
  bench::print_head(model, o, "pinocchio_cg", build.c_str());
  const bench::Batch b = bench::draw(model, o.free, o.count, o.seed);
  const std::vector<std::string> flags = bench::split(cflags, ' ');

  const std::vector<std::string> names = {"aba", "rnea", "crba_sym", "gravity", "aba_derivatives"};
  auto prepared = [&](auto & generator, const char * fn) {
    auto [seconds, compiled] = generator.prepare(flags);
    std::printf(
      "{\"impl\":\"pinocchio_cg\",\"model\":%s,\"prepare\":\"%s\",\"seconds\":%.2f,"
      "\"compiled\":%s}\n",
      bench::json_string(o.name).c_str(), fn, seconds, compiled ? "true" : "false");
    std::fflush(stdout);
  };
  auto run = [&](const char * fn, auto call, auto sum) {
    bench::time_function("pinocchio_cg", o.name, fn, call, sum, o.count, o.reps, build.c_str());
  };
  const std::string lib = o.name + "_";

  if (bench::wanted(o.only, names, "aba"))
  {
    Opened<pinocchio::CodeGenABA<double>> g(model, "aba", lib + "aba");
    prepared(g, "aba");
    run(
      "aba",
      [&](int k) {
        g.evalFunction(b.q[k], b.v[k], b.tau[k]);
        return g.out()[0];
      },
      [&](int k) {
        g.evalFunction(b.q[k], b.v[k], b.tau[k]);
        return g.out().sum();
      });
  }
  if (bench::wanted(o.only, names, "rnea"))
  {
    Opened<pinocchio::CodeGenRNEA<double>> g(model, "rnea", lib + "rnea");
    prepared(g, "rnea");
    run(
      "rnea",
      [&](int k) {
        g.evalFunction(b.q[k], b.v[k], b.a[k]);
        return g.out()[0];
      },
      [&](int k) {
        g.evalFunction(b.q[k], b.v[k], b.a[k]);
        return g.out().sum();
      });
  }
  if (bench::wanted(o.only, names, "crba_sym"))
  {
    // The generated CRBA returns the upper triangle, which evalFunction
    // unpacks into M (nv x nq: its first nv columns are the matrix); the
    // lower triangle is copied from it, as pinocchio_bench's crba_sym does.
    Opened<pinocchio::CodeGenCRBA<double>> g(model, "crba", lib + "crba");
    prepared(g, "crba_sym");
    auto symmetric = [&](int k) {
      g.evalFunction(b.q[k]);
      auto m = g.M.leftCols(n);
      m.template triangularView<Eigen::StrictlyLower>() =
        m.transpose().template triangularView<Eigen::StrictlyLower>();
      return m;
    };
    run(
      "crba_sym", [&](int k) { return symmetric(k)(n - 1, 0); },
      [&](int k) { return symmetric(k).sum(); });
  }
  if (bench::wanted(o.only, names, "gravity"))
  {
    Opened<CodeGenGravity> g(model, "gravity", lib + "gravity");
    prepared(g, "gravity");
    run(
      "gravity",
      [&](int k) {
        g.evalFunction(b.q[k]);
        return g.out()[0];
      },
      [&](int k) {
        g.evalFunction(b.q[k]);
        return g.out().sum();
      });
  }
  if (bench::wanted(o.only, names, "aba_derivatives"))
  {
    // The generated function's output is ddq_dq, ddq_dv and Minv, each nv x
    // nv row-major; the checksum is pinocchio_bench's: every entry of the
    // first two, and of the symmetric M^-1 from its upper triangle.
    Opened<pinocchio::CodeGenABADerivatives<double>> g(model, "partial_aba", lib + "aba_derivatives");
    prepared(g, "aba_derivatives");
    auto sum = [&]() {
      const Eigen::VectorXd & y = g.out();
      double total = y.head(2 * n * n).sum();
      for (int i = 0; i < n; ++i)
        for (int j = i; j < n; ++j)
          total += (i == j ? 1.0 : 2.0) * y[2 * n * n + i * n + j];
      return total;
    };
    run(
      "aba_derivatives",
      [&](int k) {
        g.evalFunction(b.q[k], b.v[k], b.tau[k]);
        return g.out()[n * n + n * n - 1];
      },
      [&](int k) {
        g.evalFunction(b.q[k], b.v[k], b.tau[k]);
        return sum();
      });
  }
  return 0;
}
