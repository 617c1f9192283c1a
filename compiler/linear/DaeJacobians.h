// The residuals F(t, y, y', p) of a DAE, its outputs g, and their partial derivatives with respect
// to y, y' and the model's inputs, taken symbolically once (sparse) and evaluated at any point.
#pragma once

#include <Eigen/Dense>
#include <memory>
#include <vector>

#include "dae/Dae.h"
#include "symbolic/Expr.h"

namespace qdot::linear {

/// The values of one point: y and y' by variable, with the parameters and the time, written into
/// a symbol-indexed array for evaluation.
class PointValues {
 public:
  PointValues(const dae::Dae& d, const sym::Context& ctx, const std::vector<double>& parameters, double time);
  Eigen::VectorXd y, yp;  ///< by variable (yp of an algebraic variable is unused)
  /// The symbol values for sym::evaluate (y and yp written in).
  const std::vector<double>& symbols();

 private:
  const dae::Dae& d_;
  std::vector<double> symbols_;
};

/// F, g and their derivatives at a point: rows are equations (outputs for the G matrices),
/// columns variables (Y, Yp, GY, GYp) or inputs (U, GU). Yp's columns of algebraic variables are zero.
struct JacobianValues {
  Eigen::VectorXd F, g;
  Eigen::MatrixXd Y, Yp, U, GY, GYp, GU;
};

class DaeJacobians {
 public:
  /// `inputs`: indices in dae.parameters of the inputs u.
  DaeJacobians(const dae::Dae& d, sym::Context& ctx, const std::vector<int>& inputs);
  ~DaeJacobians();
  /// False if a value is not finite (or a residual depends on a symbol that is none of y, y', p, t).
  bool evaluate(PointValues& p, JacobianValues& out);

 private:
  struct Entry {
    int row, column, root;  ///< row: equation (then outputs), column: y, y', u positions
  };
  size_t equations_, outputs_, variables_, inputs_;
  std::vector<Entry> entries_;
  std::vector<int> valueRoots_;  ///< the root of each row's value
  std::unique_ptr<sym::Evaluator> evaluator_;
  std::vector<double> values_;  ///< of the roots, scratch
};

}  // namespace qdot::linear
