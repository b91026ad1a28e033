// sphc: the .sph compiler driver. The lowering reads top to bottom, one pass per line:
//   modules = parse; plan = sema; plan = bodies; plan = prune; ... cpp = emit; exe = build
// `--dump-after=PASS` prints the state after PASS and stops; `--report` prints the plan.
#include "analysis/Passes.h"
#include "body/BodyAnalysis.h"
#include "codegen/CppEmitter.h"
#include "driver/Build.h"
#include "frontend/ASTPrinter.h"
#include "frontend/Diagnostics.h"
#include "sema/Options.h"
#include "sema/Sema.h"

#include "llvm/Support/CommandLine.h"
#include "llvm/Support/FileSystem.h"
#include "llvm/Support/InitLLVM.h"
#include "llvm/Support/Path.h"
#include "llvm/Support/raw_ostream.h"

#include <chrono>

using namespace sphc;
namespace cl = llvm::cl;

static cl::OptionCategory SphcCat("sphc options");
static cl::opt<std::string> InputFile(cl::Positional, cl::desc("<scene.sph>"), cl::Required,
                                      cl::cat(SphcCat));
static cl::opt<std::string> OutputFile("o", cl::desc("Executable to write (default: the scene "
                                                     "file's name without .sph)"),
                                       cl::value_desc("file"), cl::cat(SphcCat));
static cl::opt<std::string> Backend("backend", cl::desc("serial (default), openmp or opencl"),
                                    cl::init("serial"), cl::cat(SphcCat));
static cl::opt<std::string> Precision("precision",
                                      cl::desc("Floating point the scene computes in: double "
                                               "(default; on OpenCL it needs fp64) or single"),
                                      cl::init("double"), cl::cat(SphcCat));
static cl::opt<std::string> Emit("emit",
                                 cl::desc("What to produce: exe (default), cpp (the generated "
                                          "C++ on stdout), opencl (the OpenCL C kernels of "
                                          "--backend=opencl), plan, ast"),
                                 cl::init("exe"), cl::cat(SphcCat));
static cl::opt<std::string> DumpAfter("dump-after",
                                      cl::desc("Print the state after a pass and stop: parse, "
                                               "sema, bodies, prune, properties, hazards, pairs, "
                                               "ghosts, schedule"),
                                      cl::value_desc("pass"), cl::cat(SphcCat));
static cl::opt<bool> Report("report", cl::desc("Print the execution plan the compiler derived "
                                               "(arrays, properties, groups, pruned equations)"),
                            cl::cat(SphcCat));
static cl::list<std::string> Defines("D",
                                     cl::desc("Choose a compile-time option of the scene, as in "
                                              "-D scheme=edac (see `option` in the scene)"),
                                     cl::value_desc("name=choice"), cl::Prefix,
                                     cl::cat(SphcCat));
static cl::list<std::string> IncludeDirs("I", cl::desc("Add a directory to the import path"),
                                         cl::value_desc("dir"), cl::Prefix, cl::cat(SphcCat));
static cl::opt<std::string> Cxx("cxx", cl::desc("C++ compiler for the generated code"),
                                cl::cat(SphcCat));
static cl::opt<std::string> CxxFlags("cxxflags", cl::desc("Flags for the generated code "
                                                          "(replace the defaults)"),
                                     cl::cat(SphcCat));
static cl::opt<bool> NoCache("no-cache", cl::desc("Always rebuild, ignoring the cache"),
                             cl::cat(SphcCat));
static cl::opt<bool> WarningsAsErrors("Werror", cl::desc("Treat warnings as errors"),
                                      cl::cat(SphcCat));
static cl::opt<bool> Verbose("v", cl::desc("Print the build command and timings"),
                             cl::cat(SphcCat));

static int fail() { return 1; }

int main(int argc, char** argv) {
  llvm::InitLLVM init(argc, argv);
  cl::HideUnrelatedOptions(SphcCat);
  cl::SetVersionPrinter([](llvm::raw_ostream& os) { os << "sphc 0.1.0\n"; });
  cl::ParseCommandLineOptions(argc, argv,
                              "sphc: compiles a .sph SPH scene into a solver executable\n");
  auto t0 = std::chrono::steady_clock::now();
  auto log = [&](const char* what) {
    if (!Verbose) return;
    double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    llvm::errs() << "sphc: " << what << " done at " << llvm::format("%.3f", s) << " s\n";
  };

  if (Backend != "serial" && Backend != "openmp" && Backend != "opencl") {
    llvm::errs() << "sphc: error: unknown backend '" << Backend
                 << "'; backends are: serial, openmp, opencl\n";
    return fail();
  }
  if (Precision != "double" && Precision != "single") {
    llvm::errs() << "sphc: error: unknown --precision '" << Precision
                 << "'; it is double or single\n";
    return fail();
  }
  static const char* passes[] = {"parse",      "options", "sema",    "bodies", "prune",
                                 "properties", "hazards", "pairs",   "ghosts", "schedule"};
  if (!DumpAfter.empty() &&
      std::find(std::begin(passes), std::end(passes), DumpAfter) == std::end(passes)) {
    llvm::errs() << "sphc: error: unknown pass '" << DumpAfter
                 << "' for --dump-after; passes are: parse, options, sema, bodies, prune, "
                    "properties, hazards, pairs, ghosts, schedule\n";
    return fail();
  }
  if (Emit != "exe" && Emit != "cpp" && Emit != "opencl" && Emit != "plan" && Emit != "ast") {
    llvm::errs() << "sphc: error: unknown --emit kind '" << Emit
                 << "'; kinds are: exe, cpp, opencl, plan, ast\n";
    return fail();
  }

  Install install = locateInstall(argv[0]);
  // A solver of --backend=opencl needs the OpenCL runtime, built only where CMake found
  // OpenCL; say so before any work (--emit=cpp/opencl do not need it).
  if (Backend == "opencl" && Emit == "exe") {
    std::string why;
    if (!openclAvailable(install, why)) {
      llvm::errs() << "sphc: error: --backend=opencl is not available in this build: " << why
                   << "\n";
      return fail();
    }
  }
  llvm::SourceMgr sm;
  DiagnosticEngine diags(sm);
  diags.setWarningsAsErrors(WarningsAsErrors);

  // --- front end ---------------------------------------------------------------------
  std::vector<std::string> includes(IncludeDirs.begin(), IncludeDirs.end());
  bool parseOnly = Emit == "ast" || DumpAfter == "parse";
  auto modules = loadModules(InputFile, parseOnly ? std::vector<std::string>{} : includes,
                             install.stdlibDir, diags);
  log("parse");
  if (parseOnly) {
    if (!modules.empty() && !diags.hasErrors()) printModule(*modules.front(), llvm::outs(), diags);
    return diags.hasErrors() ? fail() : 0;
  }
  if (modules.empty() || diags.hasErrors()) return fail();

  // --- compile-time options, semantic analysis and the analysis passes --------------------
  std::vector<ChosenOption> options;
  std::vector<std::string> defines(Defines.begin(), Defines.end());
  if (!selectOptions(modules, defines, diags, options)) return fail();
  log("options");
  if (DumpAfter == "options") {
    printModule(*modules.front(), llvm::outs(), diags);
    return 0;
  }
  auto plan = buildPlan(modules, diags);
  log("sema");
  if (!plan || diags.hasErrors()) return fail();
  plan->options = options;
  auto dump = [&](const char* pass) {
    if (DumpAfter != pass) return false;
    printPlan(*plan, llvm::outs(), false);
    return true;
  };
  if (dump("sema")) return 0;

  {
    std::vector<BodySource> sources;
    for (const auto& b : plan->bodies) sources.push_back(b.source);
    auto facts = BodyAnalyzer(diags).analyze(sources);
    for (size_t i = 0; i < facts.size() && i < plan->bodies.size(); ++i)
      plan->bodies[i].facts = facts[i];
  }
  log("bodies");
  if (diags.hasErrors()) return fail();
  if (dump("bodies")) return 0;

  if (!pruneEquations(*plan, diags)) return fail();
  if (dump("prune")) return 0;
  if (!inferProperties(*plan, diags)) return fail();
  if (dump("properties")) return 0;
  if (!checkHazards(*plan, diags)) return fail();
  if (dump("hazards")) return 0;
  if (!selectPairQuantities(*plan, diags)) return fail();
  if (dump("pairs")) return 0;
  if (!selectGhostProperties(*plan, diags)) return fail();
  if (dump("ghosts")) return 0;
  log("analysis");
  if (diags.hasErrors()) return fail();

  if (Report) printPlan(*plan, llvm::outs(), true);
  if (Emit == "plan") {
    if (!Report) printPlan(*plan, llvm::outs(), true);
    return 0;
  }

  // --- the back half: schedule, code generation and build ----------------------------
  auto schedule = buildSchedule(*plan);
  log("schedule");
  if (DumpAfter == "schedule") {
    printSchedule(*schedule, diags, llvm::outs());
    return 0;
  }
  EmitOptions emitOpts{Backend, Precision};
  if (Emit == "opencl") {
    llvm::outs() << emitOpenCL(*schedule, diags, emitOpts);
    return 0;
  }
  std::string cpp = emitCpp(*schedule, diags, emitOpts);
  log("emit");
  if (Emit == "cpp") {
    llvm::outs() << cpp;
    return 0;
  }
  if (Report && OutputFile.empty()) return 0;  // `sphc scene.sph --report` only reports

  std::string output = OutputFile;
  if (output.empty()) output = llvm::sys::path::stem(InputFile).str();
  BuildRequest req;
  req.cpp = cpp;
  req.output = output;
  req.cxx = Cxx;
  req.cxxflags = CxxFlags;
  req.backend = Backend;
  req.useCache = !NoCache;
  req.verbose = Verbose;
  BuildResult res = buildExecutable(install, req);
  log("build");
  if (!res.ok) {
    llvm::errs() << "sphc: error: " << res.message << "\n";
    return fail();
  }
  if (Verbose)
    llvm::errs() << "sphc: wrote " << output << (res.cached ? " (cached)" : "") << " in "
                 << llvm::format("%.2f", res.seconds) << " s\n";
  return 0;
}
