// Makes angle outputs continuous from one result row to the next (QdotModel::outputKinds). An
// angle computed with atan2 jumps by 2π where it crosses ±π; a rigid body's z-x-z Euler angles
// (ψ, θ, φ) also jump by π where the body passes through θ = 0, the configuration where ψ and φ
// are not separately defined. The unwrapper keeps the previous row and picks the equivalent value
// nearest to it, so a time series of angles reads as the motion it describes.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace qdot::rt {

class AngleUnwrapper {
 public:
  /// kinds: [nOutputs] as in model_abi.h (0 plain, 1 angle, 2 first of a z-x-z triple), or empty.
  explicit AngleUnwrapper(std::span<const int32_t> kinds);

  /// Adjusts the outputs of the next row in place (the first row is kept as computed).
  ///  angle:  x + 2πk, k the integer that brings it nearest the previous row's value.
  ///  triple: with a = (ψ+φ)/2 and b = (ψ−φ)/2 (the half-angle sum and difference, which the
  ///  quaternion gives continuously up to 2π and, at θ = 0, π), a + 2πk nearest the previous a and
  ///  b + πj nearest the previous b; an odd j means the body went through θ = 0, and θ changes sign
  ///  (ψ + π, −θ, φ − π is the same rotation as ψ, θ, φ). The output interval must resolve the motion:
  ///  less than half a turn of ψ ± φ between rows.
  void apply(std::span<double> outputs);

  bool active() const { return !kinds_.empty(); }

 private:
  std::vector<int32_t> kinds_;
  std::vector<double> previous_;
  bool first_ = true;
};

}  // namespace qdot::rt
