// F, g and their sparse symbolic Jacobians (see DaeJacobians.h).
#include "linear/DaeJacobians.h"

#include <cmath>
#include <limits>

namespace qdot::linear {

PointValues::PointValues(const dae::Dae& d, const sym::Context& ctx, const std::vector<double>& parameters, double time)
    : y(Eigen::VectorXd::Zero(d.variables.size())),
      yp(Eigen::VectorXd::Zero(d.variables.size())),
      d_(d),
      symbols_(ctx.symbolCount(), std::numeric_limits<double>::quiet_NaN()) {
  for (size_t k = 0; k < d.parameters.size(); ++k) symbols_[d.parameters[k].symbol->symbolId] = parameters[k];
  symbols_[d.time->symbolId] = time;
}

const std::vector<double>& PointValues::symbols() {
  for (size_t j = 0; j < d_.variables.size(); ++j) {
    symbols_[d_.variables[j].y->symbolId] = y(j);
    if (d_.variables[j].yp) symbols_[d_.variables[j].yp->symbolId] = yp(j);
  }
  return symbols_;
}

DaeJacobians::DaeJacobians(const dae::Dae& d, sym::Context& ctx, const std::vector<int>& inputs)
    : equations_(d.equations.size()),
      outputs_(d.outputs.size()),
      variables_(d.variables.size()),
      inputs_(inputs.size()) {
  // Column c: y of variable c (c < nv), y' of variable c − nv (c < 2nv), input c − 2nv.
  std::vector<sym::Expr> symbols;
  std::vector<int> columnOf;  // of each symbol
  for (size_t j = 0; j < variables_; ++j) symbols.push_back(d.variables[j].y), columnOf.push_back(static_cast<int>(j));
  for (size_t j = 0; j < variables_; ++j)
    if (d.variables[j].yp) symbols.push_back(d.variables[j].yp), columnOf.push_back(static_cast<int>(variables_ + j));
  for (size_t k = 0; k < inputs.size(); ++k)
    symbols.push_back(d.parameters[inputs[k]].symbol), columnOf.push_back(static_cast<int>(2 * variables_ + k));
  sym::PartialDerivatives pd(ctx, symbols);
  std::vector<sym::Expr> roots;
  auto add = [&](int row, sym::Expr e) {
    valueRoots_.push_back(static_cast<int>(roots.size()));
    roots.push_back(e);
    std::vector<uint32_t> in(pd.symbolsIn(e).begin(), pd.symbolsIn(e).end());
    std::vector<sym::Expr> gradient(pd.gradient(e).begin(), pd.gradient(e).end());
    for (size_t i = 0; i < in.size(); ++i) {
      entries_.push_back({row, columnOf[in[i]], static_cast<int>(roots.size())});
      roots.push_back(gradient[i]);
    }
  };
  for (size_t i = 0; i < equations_; ++i) add(static_cast<int>(i), d.equations[i].residual);
  for (size_t i = 0; i < outputs_; ++i) add(static_cast<int>(equations_ + i), d.outputs[i].value);
  evaluator_ = std::make_unique<sym::Evaluator>(roots);
  values_.resize(roots.size());
}

DaeJacobians::~DaeJacobians() = default;

bool DaeJacobians::evaluate(PointValues& p, JacobianValues& out) {
  evaluator_->run(p.symbols(), values_);
  size_t n = equations_, m = outputs_, nv = variables_, nu = inputs_;
  out.F.resize(n), out.g.resize(m);
  for (size_t i = 0; i < n + m; ++i) (i < n ? out.F(i) : out.g(i - n)) = values_[valueRoots_[i]];
  out.Y.setZero(n, nv), out.Yp.setZero(n, nv), out.U.setZero(n, nu);
  out.GY.setZero(m, nv), out.GYp.setZero(m, nv), out.GU.setZero(m, nu);
  for (const Entry& e : entries_) {
    bool output = static_cast<size_t>(e.row) >= n;
    int r = output ? e.row - static_cast<int>(n) : e.row;
    size_t c = e.column;
    double v = values_[e.root];
    if (c < nv)
      (output ? out.GY : out.Y)(r, c) = v;
    else if (c < 2 * nv)
      (output ? out.GYp : out.Yp)(r, c - nv) = v;
    else
      (output ? out.GU : out.U)(r, c - 2 * nv) = v;
  }
  for (double v : values_)
    if (!std::isfinite(v)) return false;
  return true;
}

}  // namespace qdot::linear
