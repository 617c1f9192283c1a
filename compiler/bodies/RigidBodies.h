// Rigid bodies (spec §8, textbook chapter 6): lowers every `body NAME(...)` declaration of a parsed
// file, with the `gravity`, `torque(NAME)` and `force(NAME, at = …)` statements that act on it,
// to a component of a class generated for that body. The generated class states Euler's dynamic
// equations, the quaternion kinematics and the body's outputs (Euler angles, angular momentum,
// energy) as ordinary qdot equations, so every later stage (sema, flatten, the DAE, the kernels,
// index reduction when a body is constrained) treats a body like any other component.
#pragma once

#include "ast/AST.h"
#include "support/Diagnostic.h"
#include "support/SourceManager.h"

namespace qdot::bodies {

/// Rewrites file in place: each body declaration becomes a component of a class named
/// `__body_<Class>_<name>` added next to the class that declares it; the body statements leave
/// the mechanics section and become the component's modifiers. Reports located errors (E07xx)
/// for a body without mass or inertia, an unknown attribute, an inertia that is not physical, a
/// body statement naming no body. A file without bodies is left untouched.
void lowerRigidBodies(ast::StoredDefinition& file, SourceManager& sources, DiagnosticEngine& diags);

}  // namespace qdot::bodies
