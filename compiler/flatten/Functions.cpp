// Inlines calls of functions (Modelica's Inline = true, always): the arguments are lowered in the
// caller's scope, then the function's output binding in a frame where the function's variables
// name those values. The result is a symbolic expression of the caller's variables, so
// derivatives, Jacobians and both backends see no call at all.
#include <numbers>

#include "flatten/Flattener.h"

namespace qdot::flat {

using namespace qdot::ast;

/// The values of one call's variables, by ModelSymbol::index of the function's scope; lowered on
/// first use (a local may use a later one), a use while pending closes a cycle.
struct FunctionFrame {
  const sema::FunctionCall* call = nullptr;
  std::vector<Value> values;
  std::vector<uint8_t> state;  ///< 0 not yet, 1 pending, 2 known
};

// Lowering in a function's frame: only its variables, no loop iterators, no `end` context of the
// caller; restored on exit, also when an error or NeedFirst unwinds the call.
class Flattener::FrameGuard {
 public:
  FrameGuard(Flattener& f, FunctionFrame& frame)
      : f_(f), iterators_(std::move(f.iterators_)), end_(std::move(f.endContext_)) {
    f_.frames_.push_back(&frame);
    f_.iterators_.clear();
    f_.endContext_.clear();
  }
  ~FrameGuard() {
    f_.frames_.pop_back();
    f_.iterators_ = std::move(iterators_);
    f_.endContext_ = std::move(end_);
  }
  FrameGuard(const FrameGuard&) = delete;
  FrameGuard& operator=(const FrameGuard&) = delete;

 private:
  Flattener& f_;
  std::vector<std::pair<std::string, sym::Expr>> iterators_;
  std::vector<std::pair<const Value*, int>> end_;
};

Value Flattener::lowerFunctionCall(const sema::FunctionCall& call) {
  const sema::CheckedFunction& fn = *call.function;
  FunctionFrame frame;
  frame.call = &call;
  frame.values.resize(fn.scope->declarations.size());
  frame.state.assign(fn.scope->declarations.size(), 0);
  for (size_t i = 0; i < fn.inputs.size(); ++i) {
    const Expr* arg = call.arguments[i];
    if (!arg) continue;  // the default, lowered in the frame on first use
    Value v = lower(*arg);
    if (!v.isScalar())
      fail(arg->range, DiagCode::E0302,
           "input '" + fn.inputs[i]->name + "' of '" + fn.scope->fullName + "' must be a scalar, but this is an array of shape " +
               shapeText(v.shape),
           "functions take scalar inputs: call it once per element, {f(x[i]) for i in 1:n}");
    int slot = fn.scope->find(fn.inputs[i]->name)->index;
    frame.values[slot] = std::move(v);
    frame.state[slot] = 2;
  }
  FrameGuard guard(*this, frame);
  return functionVariable(*fn.scope->find(fn.output->name), fn.output->nameRange);
}

// A variable of the innermost function frame: an argument, or its binding (the input's default,
// the output's or a local's expression) lowered in the frame.
Value Flattener::functionVariable(const sema::ModelSymbol& s, SourceRange use) {
  FunctionFrame& frame = *frames_.back();
  uint8_t& state = frame.state[s.index];
  if (state == 2) return frame.values[s.index];
  const std::string& fname = frame.call->function->scope->fullName;
  if (state == 1)
    fail(use, DiagCode::E0312, "'" + s.decl->name + "' of function '" + fname + "' depends on itself",
         "break the cycle: the output and the locals may use one another, but not in a cycle");
  state = 1;
  Value v = Value::scalar(lowerScalar(*s.decl->binding, "a function's variable"));
  frame.values[s.index] = v;
  state = 2;
  return v;
}

// A name inside a function body: sema allows only the function's own variables (and pi).
Value Flattener::lowerFunctionName(const NameExpr& n) {
  const sema::CheckedClass& scope = *frames_.back()->call->function->scope;
  if (const sema::ModelSymbol* s = n.parts.size() == 1 ? scope.find(n.parts[0]) : nullptr)
    return functionVariable(*s, n.range);
  if (n.parts.size() == 1 && n.parts[0] == "pi") return Value::scalar(ctx_.constant(std::numbers::pi));
  fail(n.range, DiagCode::E0202, "unknown name '" + n.dotted() + "' in function '" + scope.fullName + "'");
}

}  // namespace qdot::flat
