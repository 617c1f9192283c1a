// JIT session: the compile plan (CompilePlan.h) cuts the programs into compile units (consecutive
// parts of programs at one code generator level), each lowered into its own LLVMContext and module and
// compiled to an object in memory by a pool of threads; LLJIT then links the objects in-process
// and hands out the part functions. Separate contexts and target machines per thread make the
// units independent, so compile time divides by the number of cores on large models; small ones
// are one unit per program. libm functions the code calls (tan, atan2, ...) resolve against the
// running process.
#include "llvm/Jit.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <map>
#include <mutex>
#include <thread>

#include <llvm/ExecutionEngine/Orc/ExecutionUtils.h>
#include <llvm/ExecutionEngine/Orc/JITTargetMachineBuilder.h>
#include <llvm/ExecutionEngine/Orc/LLJIT.h>
#include <llvm/IR/LLVMContext.h>
#include <llvm/IR/LegacyPassManager.h>
#include <llvm/IR/Module.h>
#include <llvm/IR/Verifier.h>
#include <llvm/Passes/PassBuilder.h>
#include <llvm/Support/SmallVectorMemoryBuffer.h>
#include <llvm/Support/TargetSelect.h>
#include <llvm/Target/TargetMachine.h>

#include "llvm/Codegen.h"
#include "llvm/CompilePlan.h"

namespace qdot::llvmbackend {

struct JitSession::Impl {
  std::unique_ptr<llvm::orc::LLJIT> jit;
};

JitSession::JitSession() : impl_(std::make_unique<Impl>()) {}
JitSession::~JitSession() = default;

namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

void initialiseNativeTarget() {
  static std::once_flag once;
  std::call_once(once, [] {
    llvm::InitializeNativeTarget();
    llvm::InitializeNativeTargetAsmPrinter();
  });
}

llvm::CodeGenOpt::Level codegenLevel(int optLevel) {
  switch (optLevel) {
    case 0: return llvm::CodeGenOpt::None;
    case 1: return llvm::CodeGenOpt::Less;
    case 2: return llvm::CodeGenOpt::Default;
    default: return llvm::CodeGenOpt::Aggressive;
  }
}

llvm::OptimizationLevel passLevel(int optLevel) {
  switch (optLevel) {
    case 1: return llvm::OptimizationLevel::O1;
    case 2: return llvm::OptimizationLevel::O2;
    default: return llvm::OptimizationLevel::O3;
  }
}

// The per-module default pipeline (nothing at level 0: the code is already minimal SSA).
void optimise(llvm::Module& m, llvm::TargetMachine* tm, int optLevel) {
  if (optLevel <= 0) return;
  llvm::LoopAnalysisManager lam;
  llvm::FunctionAnalysisManager fam;
  llvm::CGSCCAnalysisManager cgam;
  llvm::ModuleAnalysisManager mam;
  llvm::PassBuilder pb(tm);
  pb.registerModuleAnalyses(mam);
  pb.registerCGSCCAnalyses(cgam);
  pb.registerFunctionAnalyses(fam);
  pb.registerLoopAnalyses(lam);
  pb.crossRegisterProxies(lam, fam, cgam, mam);
  pb.buildPerModuleDefaultPipeline(passLevel(optLevel)).run(m, mam);
}

template <typename T>
bool take(llvm::Expected<T>& value, std::string& error, const char* what) {
  if (value) return true;
  error = std::string(what) + ": " + llvm::toString(value.takeError());
  return false;
}

/// A planned unit being compiled: its object, or why not, and what each phase cost.
struct CompileUnit {
  PlannedUnit plan;
  std::unique_ptr<llvm::MemoryBuffer> object;
  std::string error;
  double lower = 0, optimise = 0, codegen = 0;
};

unsigned threadCount(const JitOptions& o) {
  unsigned hw = std::max(1u, std::thread::hardware_concurrency());
  return o.threads ? o.threads : std::min(hw, 8u);
}

/// Compiles units to objects; one per thread (target machines are not shared between threads).
class UnitCompiler {
 public:
  UnitCompiler(const kernel::KernelModule& k, const PerProgram<ProgramPlan>& plans,
               const llvm::orc::JITTargetMachineBuilder& host, const JitOptions& o)
      : k_(k), plans_(plans), host_(host), pipelineLevel_(o.pipelineLevel), verify_(o.verifyIR), cancel_(o.cancel) {}

  void compile(CompileUnit& u) {
    if (cancel_ && cancel_->load()) {
      u.error = "cancelled";
      return;
    }
    llvm::TargetMachine* tm = machine(u.plan.level, u.error);
    if (!tm) return;
    auto start = Clock::now();
    llvm::LLVMContext ctx;
    const Segment& head = u.plan.segments.front();
    llvm::Module m(partName(plans_[programIndex(head.program)].name, head.first), ctx);
    m.setDataLayout(tm->createDataLayout());
    m.setTargetTriple(tm->getTargetTriple().str());
    for (const Segment& s : u.plan.segments) {
      const ProgramPlan& plan = plans_[programIndex(s.program)];
      lowerParts(k_.program(s.program), plan.split, s.first, s.last, plan.name, m, false, IndexTables::InPlace);
    }
    std::string verifyErrors;
    llvm::raw_string_ostream os(verifyErrors);
    if (verify_ && llvm::verifyModule(m, &os)) {
      u.error = "internal error: invalid LLVM IR: " + os.str();
      return;
    }
    u.lower = secondsSince(start);
    start = Clock::now();
    optimise(m, tm, pipelineLevel_ >= 0 ? pipelineLevel_ : u.plan.level);
    u.optimise = secondsSince(start);
    start = Clock::now();
    llvm::SmallVector<char, 0> buffer;
    llvm::raw_svector_ostream out(buffer);
    llvm::legacy::PassManager pm;
    if (tm->addPassesToEmitFile(pm, out, nullptr, llvm::CGFT_ObjectFile)) {
      u.error = "LLVM cannot emit object code for this host";
      return;
    }
    pm.run(m);
    u.object = std::make_unique<llvm::SmallVectorMemoryBuffer>(std::move(buffer), m.getName(), false);
    u.codegen = secondsSince(start);
  }

 private:
  llvm::TargetMachine* machine(int level, std::string& error) {
    auto& tm = machines_[level];
    if (!tm) {
      llvm::orc::JITTargetMachineBuilder builder = host_;
      builder.setCodeGenOptLevel(codegenLevel(level));
      auto created = builder.createTargetMachine();
      if (!take(created, error, "LLVM target machine")) return nullptr;
      tm = std::move(*created);
    }
    return tm.get();
  }

  const kernel::KernelModule& k_;
  const PerProgram<ProgramPlan>& plans_;
  const llvm::orc::JITTargetMachineBuilder& host_;
  int pipelineLevel_;
  bool verify_;
  const std::atomic<bool>* cancel_;
  std::map<int, std::unique_ptr<llvm::TargetMachine>> machines_;
};

// Runs `compile` on every unit, largest first, on `threads` threads (the caller's included).
// `whileWaiting` runs on the calling thread first, overlapping the workers.
template <class Compile, class Work>
void compileAll(std::vector<CompileUnit>& units, unsigned threads, Compile makeCompiler, Work whileWaiting) {
  std::vector<size_t> order(units.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return units[a].plan.instructions > units[b].plan.instructions; });
  std::atomic<size_t> next{0};
  auto worker = [&] {
    UnitCompiler c = makeCompiler();
    for (size_t i; (i = next.fetch_add(1)) < order.size();) c.compile(units[order[i]]);
  };
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < std::min<size_t>(threads, units.size()); ++t) pool.emplace_back(worker);
  whileWaiting();
  worker();
  for (std::thread& t : pool) t.join();
}

}  // namespace

Result<std::unique_ptr<JitSession>> JitSession::compile(const kernel::KernelModule& k, const JitOptions& options,
                                                        JitStats* stats) {
  std::string error;
  auto wallStart = Clock::now();
  initialiseNativeTarget();
  JitStats local;
  JitStats& st = stats ? *stats : local;
  auto host = llvm::orc::JITTargetMachineBuilder::detectHost();
  if (!take(host, error, "LLVM cannot target this host")) return Error{error};
  host->setRelocationModel(llvm::Reloc::PIC_);

  unsigned threads = threadCount(options);
  CompilePlan plan = planCompile(k, options, threads);
  const PerProgram<ProgramPlan>& plans = plan.programs;
  std::vector<CompileUnit> units;
  for (PlannedUnit& u : plan.units) units.push_back(CompileUnit{std::move(u)});

  // The JIT itself is created while the workers compile.
  std::unique_ptr<llvm::orc::LLJIT> jit;
  double createSeconds = 0;
  compileAll(
      units, threads, [&] { return UnitCompiler(k, plans, *host, options); },
      [&] {
        auto start = Clock::now();
        auto created = llvm::orc::LLJITBuilder().setJITTargetMachineBuilder(*host).create();
        if (take(created, error, "cannot create the LLVM JIT")) jit = std::move(*created);
        createSeconds = secondsSince(start);
      });
  if (!jit) return Error{error};
  for (const CompileUnit& u : units)
    if (!u.error.empty()) return Error{u.error};

  auto start = Clock::now();
  auto& dylib = jit->getMainJITDylib();
  auto process = llvm::orc::DynamicLibrarySearchGenerator::GetForCurrentProcess(jit->getDataLayout().getGlobalPrefix());
  if (!take(process, error, "cannot resolve libm symbols")) return Error{error};
  dylib.addGenerator(std::move(*process));
  for (CompileUnit& u : units)
    if (auto err = jit->addObjectFile(std::move(u.object))) return Error{"LLVM JIT: " + llvm::toString(std::move(err))};
  llvm::orc::SymbolLookupSet names;
  for (const ProgramPlan& plan : plans)
    for (uint32_t p = 0; plan.compiled && p < plan.split.parts; ++p) names.add(jit->mangleAndIntern(partName(plan.name, p)));
  auto symbols = jit->getExecutionSession().lookup(llvm::orc::makeJITDylibSearchOrder({&dylib}), std::move(names));
  if (!take(symbols, error, "LLVM JIT lookup")) return Error{error};

  std::unique_ptr<JitSession> session(new JitSession());
  for (size_t i = 0; i < kModelProgramCount; ++i) {
    const ProgramPlan& p = plans[i];
    for (uint32_t part = 0; p.compiled && part < p.split.parts; ++part) {
      auto address = (*symbols)[jit->mangleAndIntern(partName(p.name, part))].getAddress();
      session->parts_[i].push_back(reinterpret_cast<ProgramFn>(static_cast<uintptr_t>(address)));
    }
    session->spill_[i] = p.split.spillSlots;
    st.functions[i] = p.compiled ? p.split.parts : 0;
    st.spillSlots[i] = p.split.spillSlots;
  }
  session->impl_->jit = std::move(jit);
  for (const CompileUnit& u : units) st.lowerSeconds += u.lower, st.optimiseSeconds += u.optimise, st.codegenSeconds += u.codegen;
  st.linkSeconds = createSeconds + secondsSince(start);
  st.threads = std::min<unsigned>(threads, static_cast<unsigned>(std::max<size_t>(1, units.size())));
  st.units = static_cast<unsigned>(units.size());
  st.wallSeconds = secondsSince(wallStart);
  return session;
}

}  // namespace qdot::llvmbackend
