// The serial vector operations compiled by qdot (ida/SerialVectorOps.h) against SUNDIALS' own, bit
// for bit: the same operation on two sets of vectors holding the same numbers, one set with
// SUNDIALS' operations table and one with qdot's, must leave every vector and every returned value
// identical. The numbers include zeros of both signs, an infinity and a NaN, the coefficients every
// special case SUNDIALS distinguishes (±1, a = b, a = -b, 0), and the vectors every aliasing an
// integrator uses (z = x, z = y, the first of a combination written in place, and a later one).
// The length is not a multiple of the operations' block of elements.
#include <gtest/gtest.h>

#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <random>
#include <vector>

#include "ida/SerialVectorOps.h"

namespace qdot::rt::test {
namespace {

constexpr sunindextype kLength = 1037;
constexpr int kVectors = 8;

class SerialVectorOps : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_EQ(SUNContext_Create(nullptr, &context_), 0);
    std::mt19937 random(11);
    std::uniform_real_distribution<double> value(-2, 2);
    for (int k = 0; k < kVectors; ++k) {
      N_Vector s = N_VNew_Serial(kLength, context_), q = N_VNew_Serial(kLength, context_);
      N_VEnableFusedOps_Serial(s, SUNTRUE);
      N_VEnableFusedOps_Serial(q, SUNTRUE);
      useOptimizedSerialOps(q);
      for (sunindextype i = 0; i < kLength; ++i) NV_Ith_S(s, i) = value(random);
      // Special values where an operation branches: zeros of both signs, ±1.5 and ±0.5 (the
      // constraint codes), an infinity and a NaN in the last two vectors only (the norms would be
      // NaN everywhere).
      NV_Ith_S(s, 3) = 0.0, NV_Ith_S(s, 600) = -0.0, NV_Ith_S(s, 7) = k % 2 ? 1.5 : -0.5;
      if (k >= kVectors - 2) NV_Ith_S(s, 100) = std::numeric_limits<double>::infinity(), NV_Ith_S(s, 900) = std::nan("");
      std::memcpy(N_VGetArrayPointer(q), N_VGetArrayPointer(s), kLength * sizeof(double));
      sundials_.push_back(s), ours_.push_back(q);
    }
  }
  void TearDown() override {
    for (N_Vector v : sundials_) N_VDestroy(v);
    for (N_Vector v : ours_) N_VDestroy(v);
    SUNContext_Free(&context_);
  }

  /// Runs op on SUNDIALS' vectors and on qdot's; every vector and every value op returns must be
  /// the same bits. Vectors the operation writes are copied back from SUNDIALS' set afterwards, so
  /// the next call starts from the same numbers again.
  void expectSame(const std::string& what, const std::function<std::vector<double>(std::vector<N_Vector>&)>& op) {
    std::vector<std::vector<double>> before;
    for (N_Vector v : sundials_) before.emplace_back(N_VGetArrayPointer(v), N_VGetArrayPointer(v) + kLength);
    std::vector<double> fromSundials = op(sundials_), fromOurs = op(ours_);
    ASSERT_EQ(fromSundials.size(), fromOurs.size()) << what;
    for (size_t k = 0; k < fromSundials.size(); ++k)
      EXPECT_EQ(std::memcmp(&fromSundials[k], &fromOurs[k], sizeof(double)), 0)
          << what << ": value " << k << " is " << fromOurs[k] << ", SUNDIALS " << fromSundials[k];
    for (int k = 0; k < kVectors; ++k) {
      EXPECT_EQ(std::memcmp(N_VGetArrayPointer(sundials_[k]), N_VGetArrayPointer(ours_[k]), kLength * sizeof(double)), 0)
          << what << ": vector " << k << " differs";
      std::memcpy(N_VGetArrayPointer(sundials_[k]), before[k].data(), kLength * sizeof(double));
      std::memcpy(N_VGetArrayPointer(ours_[k]), before[k].data(), kLength * sizeof(double));
    }
    ++compared_;
  }

  SUNContext context_ = nullptr;
  std::vector<N_Vector> sundials_, ours_;
  int compared_ = 0;
};

const std::vector<double> kCoefficients = {1.0, -1.0, 0.375, -0.375, 2.5, 0.0};

TEST_F(SerialVectorOps, ReplacesTheOperationsSundialsSet) {
  N_Vector q = ours_[0], s = sundials_[0];
  EXPECT_NE(q->ops->nvwrmsnorm, s->ops->nvwrmsnorm);
  EXPECT_NE(q->ops->nvlinearsum, s->ops->nvlinearsum);
  EXPECT_NE(q->ops->nvlinearcombination, s->ops->nvlinearcombination);
  // One SUNDIALS leaves unset stays unset.
  N_Vector plain = N_VNew_Serial(4, context_);
  useOptimizedSerialOps(plain);
  EXPECT_EQ(plain->ops->nvlinearcombination, nullptr);
  EXPECT_NE(plain->ops->nvlinearsum, nullptr);
  N_VDestroy(plain);
}

TEST_F(SerialVectorOps, LinearSumAndScaleMatchInEveryCase) {
  for (double a : kCoefficients)
    for (double b : kCoefficients)
      for (int target : {2, 0, 1}) {  // z apart, z = x, z = y
        expectSame("linear sum", [&](std::vector<N_Vector>& v) {
          N_VLinearSum(a, v[0], b, v[1], v[target]);
          return std::vector<double>{};
        });
      }
  for (double c : kCoefficients)
    for (int target : {1, 0}) {
      expectSame("scale", [&](std::vector<N_Vector>& v) {
        N_VScale(c, v[0], v[target]);
        return std::vector<double>{};
      });
    }
  EXPECT_EQ(compared_, 6 * 6 * 3 + 6 * 2);
}

TEST_F(SerialVectorOps, ElementwiseOperationsAndReductionsMatch) {
  for (int x : {0, kVectors - 1}) {  // plain numbers; with an infinity and a NaN
    expectSame("const, prod, div, abs, inv, addconst, compare", [&](std::vector<N_Vector>& v) {
      N_VProd(v[x], v[1], v[2]);
      N_VDiv(v[x], v[1], v[3]);
      N_VAbs(v[x], v[4]);
      N_VInv(v[x], v[5]);
      N_VAddConst(v[x], 0.25, v[6]);
      N_VCompare(0.5, v[x], v[1]);
      N_VConst(-3.5, v[x == 0 ? 7 : 0]);
      return std::vector<double>{};
    });
    expectSame("reductions", [&](std::vector<N_Vector>& v) {
      return std::vector<double>{N_VDotProd(v[x], v[1]), N_VMaxNorm(v[x]), N_VWrmsNorm(v[x], v[2]),
                                 N_VWrmsNormMask(v[x], v[2], v[3]), N_VMin(v[x]), N_VWL2Norm(v[x], v[2]),
                                 N_VL1Norm(v[x]), N_VMinQuotient(v[x], v[3]), N_VWSqrSumLocal(v[x], v[2]),
                                 N_VWSqrSumMaskLocal(v[x], v[2], v[3])};
    });
    expectSame("inverse test and constraint mask", [&](std::vector<N_Vector>& v) {
      double noZero = N_VInvTest(v[x], v[2]);
      double satisfied = N_VConstrMask(v[1], v[x], v[3]);
      return std::vector<double>{noZero, satisfied};
    });
  }
  EXPECT_EQ(compared_, 6);
}

TEST_F(SerialVectorOps, FusedOperationsMatchWithEveryAliasing) {
  std::vector<double> c = {1.0, -0.75, 0.5, 2.0, -1.25, 0.125};
  for (int count = 1; count <= 5; ++count)
    for (double first : {1.0, 0.625})
      for (int target : {7, 0, 2}) {  // z apart, z = X[0] (in place), z = X[2] (read after it is written)
        expectSame("linear combination", [&](std::vector<N_Vector>& v) {
          std::vector<double> coefficients(c.begin(), c.begin() + count);
          coefficients[0] = first;
          N_VLinearCombination(count, coefficients.data(), v.data(), v[target]);
          return std::vector<double>{};
        });
      }
  for (int count = 1; count <= 3; ++count)
    for (bool inPlace : {false, true}) {
      expectSame("scale add multi", [&](std::vector<N_Vector>& v) {
        std::vector<N_Vector> Y(v.begin() + 1, v.begin() + 1 + count), Z(v.begin() + 4, v.begin() + 4 + count);
        N_VScaleAddMulti(count, c.data(), v[0], Y.data(), inPlace ? Y.data() : Z.data());
        return std::vector<double>{};
      });
      expectSame("dot product multi", [&](std::vector<N_Vector>& v) {
        std::vector<double> dots(static_cast<size_t>(count));
        N_VDotProdMulti(count, v[0], v.data() + 1, dots.data());
        return dots;
      });
    }
  EXPECT_EQ(compared_, 5 * 2 * 3 + 3 * 2 * 2);
}

TEST_F(SerialVectorOps, VectorArrayOperationsMatch) {
  for (int count : {1, 2, 3})
    for (double a : kCoefficients)
      for (double b : {1.0, -1.0, 0.375, -0.375})
        for (int aliasing : {0, 1, 2}) {  // Z apart, Z = Y, Z = X
          expectSame("linear sum of arrays", [&](std::vector<N_Vector>& v) {
            std::vector<N_Vector> X(v.begin(), v.begin() + count), Y(v.begin() + 3, v.begin() + 3 + count);
            std::vector<N_Vector> Z(v.begin() + 5, v.begin() + 5 + count);
            N_Vector* z = aliasing == 1 ? Y.data() : aliasing == 2 ? X.data() : Z.data();
            N_VLinearSumVectorArray(count, a, X.data(), b, Y.data(), z);
            return std::vector<double>{};
          });
        }
  std::vector<double> c = {0.5, -1.0, 1.0};
  for (int count : {1, 2, 3}) {
    expectSame("scale, const and norms of arrays", [&](std::vector<N_Vector>& v) {
      std::vector<N_Vector> X(v.begin(), v.begin() + count), Z(v.begin() + 3, v.begin() + 3 + count);
      N_VScaleVectorArray(count, c.data(), X.data(), Z.data());
      N_VScaleVectorArray(count, c.data(), X.data(), X.data());
      std::vector<double> norms(2 * static_cast<size_t>(count));
      N_VWrmsNormVectorArray(count, X.data(), Z.data(), norms.data());
      N_VWrmsNormMaskVectorArray(count, X.data(), Z.data(), v[6], norms.data() + count);
      N_VConstVectorArray(count, 4.5, Z.data());
      return norms;
    });
  }
  EXPECT_EQ(compared_, 3 * 6 * 4 * 3 + 3);
}

}  // namespace
}  // namespace qdot::rt::test
