// JIT session: the programs to compile are cut into compile units (consecutive parts of one
// program at one code generator level), each lowered into its own LLVMContext and module and
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

namespace qdot::llvmbackend {

struct JitSession::Impl {
  std::unique_ptr<llvm::orc::LLJIT> jit;
};

JitSession::JitSession() : impl_(std::make_unique<Impl>()) {}
JitSession::~JitSession() = default;

namespace {

using Clock = std::chrono::steady_clock;
using kernel::ProgramId;
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

/// One compiled program: how it is split and at which level its units are compiled.
struct ProgramPlan {
  bool compiled = false;
  std::string name;  // "qdot_residual"; part k is partName(name, k)
  ProgramSplit split;
  int level = 0;
};

/// Consecutive parts [first, last) of one program.
struct Segment {
  ProgramId program{};
  uint32_t first = 0, last = 0;
};

/// Segments compiled at one level into one module and one object.
struct CompileUnit {
  int level = 0;
  std::vector<Segment> segments;
  size_t instructions = 0;
  std::unique_ptr<llvm::MemoryBuffer> object;
  std::string error;
  double lower = 0, optimise = 0, codegen = 0;
};

int levelOf(ProgramId id, const JitOptions& o) {
  if (id == ProgramId::Residual) return o.optLevel;
  if (id == ProgramId::Jacobian) return o.jacobianOptLevel >= 0 ? o.jacobianOptLevel : o.optLevel;
  return o.coldOptLevel;
}

unsigned threadCount(const JitOptions& o) {
  unsigned hw = std::max(1u, std::thread::hardware_concurrency());
  return o.threads ? o.threads : std::min(hw, 8u);
}

// Splits each compiled program and groups parts of the same level into units of about `budget`
// instructions: big enough that the per-module cost (a pass pipeline, an object to link) stays
// small (a small model is one unit per level), small enough that `threads` threads share the
// work evenly (about two units per thread on a large model).
std::vector<CompileUnit> planUnits(const kernel::KernelModule& k, const JitOptions& o, unsigned threads,
                                   std::array<ProgramPlan, kernel::kProgramCount>& plans) {
  size_t total = 0;
  for (size_t i = 0; i < kernel::kProgramCount; ++i)
    if (o.compiledPrograms & programBit(static_cast<ProgramId>(i))) total += k.programs[i].code.size();
  bool large = total > o.largeModelInstructions;
  // At most 100 000 instructions (~0.1 s at level 0): a cancelled compile stops within a unit.
  size_t budget = std::min<size_t>(std::max<size_t>(size_t{4} * o.maxInstructionsPerFunction, total / (2 * threads)),
                                   std::max<size_t>(100000, o.maxInstructionsPerFunction));
  std::vector<CompileUnit> units;
  std::map<int, size_t> filling;  // level -> index of the unit being filled at that level
  for (size_t i = 0; i < kernel::kProgramCount; ++i) {
    auto id = static_cast<ProgramId>(i);
    if (!(o.compiledPrograms & programBit(id))) continue;
    const kernel::Program& prog = k.programs[i];
    ProgramPlan& plan = plans[i];
    plan.compiled = true;
    plan.name = entryName(prog, id);
    plan.split = splitProgram(prog, o.maxInstructionsPerFunction);
    plan.level = large ? 0 : levelOf(id, o);
    for (uint32_t part = 0; part < plan.split.parts; ++part) {
      auto it = filling.find(plan.level);
      if (it == filling.end() || units[it->second].instructions >= budget) {
        units.push_back(CompileUnit{plan.level});
        it = filling.insert_or_assign(plan.level, units.size() - 1).first;
      }
      CompileUnit& u = units[it->second];
      if (u.segments.empty() || u.segments.back().program != id) u.segments.push_back({id, part, part});
      u.segments.back().last = part + 1;
      u.instructions += plan.split.end(part, prog.code.size()) - plan.split.begin(part);
    }
  }
  return units;
}

/// Compiles units to objects; one per thread (target machines are not shared between threads).
class UnitCompiler {
 public:
  UnitCompiler(const kernel::KernelModule& k, const std::array<ProgramPlan, kernel::kProgramCount>& plans,
               const llvm::orc::JITTargetMachineBuilder& host, const JitOptions& o)
      : k_(k), plans_(plans), host_(host), pipelineLevel_(o.pipelineLevel), verify_(o.verifyIR), cancel_(o.cancel) {}

  void compile(CompileUnit& u) {
    if (cancel_ && cancel_->load()) {
      u.error = "cancelled";
      return;
    }
    llvm::TargetMachine* tm = machine(u.level, u.error);
    if (!tm) return;
    auto start = Clock::now();
    llvm::LLVMContext ctx;
    const Segment& head = u.segments.front();
    llvm::Module m(partName(plans_[static_cast<size_t>(head.program)].name, head.first), ctx);
    m.setDataLayout(tm->createDataLayout());
    m.setTargetTriple(tm->getTargetTriple().str());
    for (const Segment& s : u.segments) {
      const ProgramPlan& plan = plans_[static_cast<size_t>(s.program)];
      lowerParts(k_.program(s.program), plan.split, s.first, s.last, plan.name, m, false);
    }
    std::string verifyErrors;
    llvm::raw_string_ostream os(verifyErrors);
    if (verify_ && llvm::verifyModule(m, &os)) {
      u.error = "internal error: invalid LLVM IR: " + os.str();
      return;
    }
    u.lower = secondsSince(start);
    start = Clock::now();
    optimise(m, tm, pipelineLevel_ >= 0 ? pipelineLevel_ : u.level);
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
  const std::array<ProgramPlan, kernel::kProgramCount>& plans_;
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
                   [&](size_t a, size_t b) { return units[a].instructions > units[b].instructions; });
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

std::unique_ptr<JitSession> JitSession::compile(const kernel::KernelModule& k, const JitOptions& options,
                                                std::string& error, JitStats* stats) {
  auto wallStart = Clock::now();
  initialiseNativeTarget();
  JitStats local;
  JitStats& st = stats ? *stats : local;
  auto host = llvm::orc::JITTargetMachineBuilder::detectHost();
  if (!take(host, error, "LLVM cannot target this host")) return nullptr;
  host->setRelocationModel(llvm::Reloc::PIC_);

  unsigned threads = threadCount(options);
  std::array<ProgramPlan, kernel::kProgramCount> plans;
  std::vector<CompileUnit> units = planUnits(k, options, threads, plans);

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
  if (!jit) return nullptr;
  for (const CompileUnit& u : units)
    if (!u.error.empty()) {
      error = u.error;
      return nullptr;
    }

  auto start = Clock::now();
  auto& dylib = jit->getMainJITDylib();
  auto process = llvm::orc::DynamicLibrarySearchGenerator::GetForCurrentProcess(jit->getDataLayout().getGlobalPrefix());
  if (!take(process, error, "cannot resolve libm symbols")) return nullptr;
  dylib.addGenerator(std::move(*process));
  for (CompileUnit& u : units)
    if (auto err = jit->addObjectFile(std::move(u.object))) {
      error = "LLVM JIT: " + llvm::toString(std::move(err));
      return nullptr;
    }
  llvm::orc::SymbolLookupSet names;
  for (const ProgramPlan& plan : plans)
    for (uint32_t p = 0; plan.compiled && p < plan.split.parts; ++p) names.add(jit->mangleAndIntern(partName(plan.name, p)));
  auto symbols = jit->getExecutionSession().lookup(llvm::orc::makeJITDylibSearchOrder({&dylib}), std::move(names));
  if (!take(symbols, error, "LLVM JIT lookup")) return nullptr;

  std::unique_ptr<JitSession> session(new JitSession());
  for (size_t i = 0; i < kernel::kProgramCount; ++i) {
    const ProgramPlan& plan = plans[i];
    for (uint32_t p = 0; plan.compiled && p < plan.split.parts; ++p) {
      auto address = (*symbols)[jit->mangleAndIntern(partName(plan.name, p))].getAddress();
      session->parts_[i].push_back(reinterpret_cast<ProgramFn>(static_cast<uintptr_t>(address)));
    }
    session->spill_[i] = plan.split.spillSlots;
    st.functions[i] = plan.compiled ? plan.split.parts : 0;
    st.spillSlots[i] = plan.split.spillSlots;
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
