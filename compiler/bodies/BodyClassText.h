// The qdot text of the class generated for one rigid body: its parameters, states, outputs,
// Euler's dynamic equations and the quaternion kinematics. Internal to the bodies stage.
#pragma once

#include <string>

namespace qdot::bodies {

/// What shapes the generated class (the values themselves arrive as modifiers).
struct BodyShape {
  std::string className;   ///< `__body_HeavyTop_top`
  std::string bodyName;    ///< `top`
  bool fixedPoint = false; ///< motion about the fixed reference point (else a free body)
  bool hasCm = false;      ///< `cm` given (else the reference point is the centre of mass)
  bool torqueBody = false, torqueWorld = false;
  int forces = 0;          ///< force k (1-based) has inputs force<k>[3] (world) and at<k>[3] (body)
};

/// The class text. Its equations (body axes, R = rotation body → world from the quaternion q):
///   fixed point:  Io ω̇ + ω × (Io ω) = M_o,   Io = Icm + m (|c|² E − c cᵀ)
///   free body:    m (v̇ + R (ω̇ × c + ω × (ω × c))) = m g + Σ F,   Icm ω̇ + ω × (Icm ω) = M_c
///   both:         q̇ = ½ q ⊗ (0, ω) + ½ k (1 − |q|²) q,   k = √(ω·ω + 1 s⁻²)
std::string bodyClassText(const BodyShape& shape);

}  // namespace qdot::bodies
