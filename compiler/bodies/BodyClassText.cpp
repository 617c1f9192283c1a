// Why the formulation is what it is:
// - The orientation is a quaternion (4 states), not Euler angles: no singular configuration. The
//   angles are outputs only, computed from q (psi ± phi from two atan2 of q's halves).
// - R is built from q divided by |q|², the rotation of q/|q| for any nonzero q: the dynamics do not
//   depend on the quaternion's norm at all, so a drift of the norm cannot change the motion.
// - The norm is still held at 1 (the outputs and the start values assume a unit quaternion): the
//   kinematics carry ½ k (1 − |q|²) q, which leaves the rotation unchanged (it is along q) and makes
//   d|q|²/dt = k (1 − |q|²)|q|²: a deviation decays at the rate k = √(ω·ω + 1 s⁻²), i.e. within
//   about a radian of the body's own turning. It adds no stiffness beyond the rotation rate itself
//   and, being smooth in ω, keeps the Jacobian finite at rest. (Multibody.jl stabilises a non-unit
//   quaternion the same way; a norm constraint through index reduction would add a multiplier and
//   a dummy derivative per body for no gain in accuracy.)
#include "bodies/BodyClassText.h"

#include <fmt/format.h>

namespace qdot::bodies {
namespace {

// The rotation matrix of q/|q| (body → world), scalar first.
const char* kRotation =
    "  Real qq = q[1]^2 + q[2]^2 + q[3]^2 + q[4]^2 \"squared norm of q\";\n"
    "  Real R[3, 3] = {{q[1]^2 + q[2]^2 - q[3]^2 - q[4]^2, 2*(q[2]*q[3] - q[1]*q[4]), 2*(q[2]*q[4] + q[1]*q[3])},\n"
    "                  {2*(q[2]*q[3] + q[1]*q[4]), q[1]^2 - q[2]^2 + q[3]^2 - q[4]^2, 2*(q[3]*q[4] - q[1]*q[2])},\n"
    "                  {2*(q[2]*q[4] - q[1]*q[3]), 2*(q[3]*q[4] + q[1]*q[2]), q[1]^2 - q[2]^2 - q[3]^2 + q[4]^2}}/qq\n"
    "    \"rotation body to world\";\n"
    "  Real relax = sqrt(omega*omega + 1) \"rate at which |q| returns to 1 [1/s]\";\n";

// z-x-z Euler angles of q: q = (cos(θ/2) cos((ψ+φ)/2), sin(θ/2) cos((ψ−φ)/2), sin(θ/2) sin((ψ−φ)/2),
// cos(θ/2) sin((ψ+φ)/2)). The runtime makes the triple continuous between output rows
// (runtime/output/AngleUnwrap.h): no jumps of 2π, and θ changes sign where the body passes θ = 0.
const char* kAngles =
    "  output Real psi = atan2(q[4], q[1]) + atan2(q[3], q[2]) \"precession (z-x-z Euler angle) [rad]\"\n"
    "    annotation(unwrap = \"psi\");\n"
    "  output Real theta = 2*atan2(sqrt(q[2]^2 + q[3]^2), sqrt(q[1]^2 + q[4]^2)) \"nutation [rad]\"\n"
    "    annotation(unwrap = \"theta\");\n"
    "  output Real phi = atan2(q[4], q[1]) - atan2(q[3], q[2]) \"spin [rad]\" annotation(unwrap = \"phi\");\n";

const char* kKinematics =
    "  der(q[1]) = -0.5*(q[2]*omega[1] + q[3]*omega[2] + q[4]*omega[3]) + 0.5*relax*(1 - qq)*q[1];\n"
    "  der(q[2]) = 0.5*(q[1]*omega[1] + q[3]*omega[3] - q[4]*omega[2]) + 0.5*relax*(1 - qq)*q[2];\n"
    "  der(q[3]) = 0.5*(q[1]*omega[2] + q[4]*omega[1] - q[2]*omega[3]) + 0.5*relax*(1 - qq)*q[3];\n"
    "  der(q[4]) = 0.5*(q[1]*omega[3] + q[2]*omega[2] - q[3]*omega[1]) + 0.5*relax*(1 - qq)*q[4];\n";

// The moment in body axes about `about` (the fixed point: "" ; the centre of mass: "cm") of the
// applied torques and forces (and, about a fixed point, of gravity).
std::string momentTerms(const BodyShape& s) {
  std::string m = "zeros(3)";
  if (s.torqueBody) m += " + torqueBody";
  if (s.torqueWorld) m += " + transpose(R)*torqueWorld";
  if (s.fixedPoint && s.hasCm) m += " + cross(cm, transpose(R)*(mass*gravity))";
  for (int k = 1; k <= s.forces; ++k) {
    std::string arm = s.fixedPoint || !s.hasCm ? fmt::format("at{}", k) : fmt::format("at{} - cm", k);
    m += fmt::format(" + cross({}, transpose(R)*force{})", arm, k);
  }
  return m;
}

std::string inputs(const BodyShape& s) {
  std::string t;
  if (s.torqueBody) t += "  input Real torqueBody[3] \"applied torque, body axes [N m]\";\n";
  if (s.torqueWorld) t += "  input Real torqueWorld[3] \"applied torque, world axes [N m]\";\n";
  for (int k = 1; k <= s.forces; ++k)
    t += fmt::format("  input Real force{0}[3] \"applied force, world axes [N]\";\n"
                     "  input Real at{0}[3] \"its point of application, body axes [m]\";\n", k);
  return t;
}

std::string forceSum(const BodyShape& s) {
  std::string f = "mass*gravity";
  for (int k = 1; k <= s.forces; ++k) f += fmt::format(" + force{}", k);
  return f;
}

std::string fixedPointPart(const BodyShape& s) {
  std::string io = s.hasCm ? "Icm + mass*((cm*cm)*identity(3) - {cm[i]*cm[j] for i in 1:3, j in 1:3})" : "Icm";
  std::string pe = s.hasCm ? " - mass*(gravity*(R*cm))" : "";
  return fmt::format(
      "  parameter Real Io[3, 3] = {} \"inertia about the fixed point, body axes [kg m2]\";\n"
      "  Real omega[3](each start = 0, each fixed = true) \"angular velocity, body axes [rad/s]\";\n"
      "{}{}"
      "  output Real L[3] = R*(Io*omega) \"angular momentum about the fixed point, world axes [N m s]\";\n"
      "  output Real energy = 0.5*(omega*(Io*omega)){} \"kinetic plus gravitational energy [J]\";\n"
      "equation\n{}"
      "  Io*der(omega) + cross(omega, Io*omega) = {};\n",
      io, kRotation, kAngles, pe, kKinematics, momentTerms(s));
}

std::string freeBodyPart(const BodyShape& s) {
  std::string vcm = s.hasCm ? "v + R*cross(omega, cm)" : "v";
  std::string rcm = s.hasCm ? "r + R*cm" : "r";
  std::string acm = s.hasCm ? "der(v) + R*(cross(der(omega), cm) + cross(omega, cross(omega, cm)))" : "der(v)";
  return fmt::format(
      "  Real r[3](each start = 0, each fixed = true) \"position of the reference point, world axes [m]\";\n"
      "  Real v[3](each start = 0, each fixed = true) \"velocity of the reference point, world axes [m/s]\";\n"
      "  Real omega[3](each start = 0, each fixed = true) \"angular velocity, body axes [rad/s]\";\n"
      "{2}{3}"
      "  output Real L[3] = R*(Icm*omega) \"angular momentum about the centre of mass, world axes [N m s]\";\n"
      "  output Real energy = 0.5*mass*(({0})*({0})) + 0.5*(omega*(Icm*omega)) - mass*(gravity*({1}))\n"
      "    \"kinetic plus gravitational energy [J]\";\n"
      "equation\n{4}"
      "  der(r) = v;\n"
      "  mass*({5}) = {6};\n"
      "  Icm*der(omega) + cross(omega, Icm*omega) = {7};\n",
      vcm, rcm, kRotation, kAngles, kKinematics, acm, forceSum(s), momentTerms(s));
}

}  // namespace

std::string bodyClassText(const BodyShape& s) {
  std::string head = fmt::format(
      "model {} \"rigid body {} (generated from its body declaration)\"\n"
      "  parameter Real mass \"mass [kg]\";\n"
      "  parameter Real Icm[3, 3] \"inertia about the centre of mass, body axes [kg m2]\";\n"
      "{}"
      "  parameter Real gravity[3] = {{0, 0, 0}} \"gravitational acceleration, world axes [m/s2]\";\n"
      "{}"
      "  Real q[4](start = {{1, 0, 0, 0}}, each fixed = true) \"orientation: unit quaternion body to world, scalar first\";\n",
      s.className, s.bodyName,
      s.hasCm ? "  parameter Real cm[3] \"centre of mass from the reference point, body axes [m]\";\n" : "",
      inputs(s));
  return head + (s.fixedPoint ? fixedPointPart(s) : freeBodyPart(s)) + fmt::format("end {};\n", s.className);
}

}  // namespace qdot::bodies
