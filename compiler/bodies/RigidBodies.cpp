// The body lowering: finds the `body` declarations of each class, moves the statements acting on
// them into their modifiers, checks the inertia where its value is known, and adds the generated
// class (BodyClassText) next to the class.
#include "bodies/RigidBodies.h"

#include <Eigen/Dense>
#include <cmath>
#include <map>
#include <optional>

#include "bodies/BodyClassText.h"
#include "syntax/Parser.h"

namespace qdot::bodies {
namespace {

using namespace qdot::ast;

struct BodyUse {
  Declaration* decl = nullptr;
  BodyShape shape;
  std::vector<ExprPtr> torqueBody, torqueWorld;
  std::vector<std::pair<ExprPtr, ExprPtr>> forces;  ///< (force, at); at may be null (the centre of mass)
};

bool isBodyDeclaration(const Declaration& d) { return d.typeName.size() == 1 && d.typeName[0] == "body"; }

// The sum e1 + e2 + … of the expressions (moved), located at the first.
ExprPtr sumOf(std::vector<ExprPtr>& terms) {
  ExprPtr sum = std::move(terms.front());
  for (size_t i = 1; i < terms.size(); ++i) {
    SourceRange r = SourceRange::cover(sum->range, terms[i]->range);
    SourceRange op = terms[i]->range;
    sum = std::make_unique<BinaryExpr>(r, BinaryOp::Add, op, std::move(sum), std::move(terms[i]));
  }
  return sum;
}

Modification valueModifier(std::string name, ExprPtr value, SourceRange where) {
  Modification m;
  m.name = std::move(name);
  m.nameRange = where;
  m.range = where;
  m.value = std::move(value);
  return m;
}

// The value of a constant expression of numbers and the class's parameters (with bindings), for
// the checks of the inertia at compile time; nullopt if it is not one.
class ConstantFolder {
 public:
  explicit ConstantFolder(const ClassDef& cls) {
    for (const auto& d : cls.declarations)
      if (d.variability != Variability::Continuous && d.binding && d.dims.empty()) bindings_[d.name] = d.binding.get();
  }
  std::optional<double> operator()(const Expr* e, int depth = 0) const {
    if (!e || depth > 32) return std::nullopt;
    if (auto* n = dyn_cast<NumberExpr>(e)) return n->value;
    if (auto* u = dyn_cast<UnaryExpr>(e)) {
      auto v = (*this)(u->operand.get(), depth + 1);
      return v && u->op == UnaryOp::Neg ? std::optional(-*v) : u->op == UnaryOp::Plus ? v : std::nullopt;
    }
    if (auto* name = dyn_cast<NameExpr>(e)) {
      auto it = name->parts.size() == 1 ? bindings_.find(name->parts[0]) : bindings_.end();
      return it == bindings_.end() ? std::nullopt : (*this)(it->second, depth + 1);
    }
    if (auto* b = dyn_cast<BinaryExpr>(e)) return binary(*b, depth);
    return std::nullopt;
  }

 private:
  std::map<std::string, const Expr*> bindings_;
  std::optional<double> binary(const BinaryExpr& b, int depth) const {
    auto l = (*this)(b.lhs.get(), depth + 1), r = (*this)(b.rhs.get(), depth + 1);
    if (!l || !r) return std::nullopt;
    switch (b.op) {
      case BinaryOp::Add: return *l + *r;
      case BinaryOp::Sub: return *l - *r;
      case BinaryOp::Mul: return *l * *r;
      case BinaryOp::Div: return *l / *r;
      case BinaryOp::Pow: return std::pow(*l, *r);
      default: return std::nullopt;
    }
  }
};

class ClassLowering {
 public:
  ClassLowering(ClassDef& cls, SourceManager& sources, DiagnosticEngine& diags)
      : cls_(cls), sources_(sources), diags_(diags), fold_(cls) {}

  /// The generated classes (one per body), to be added next to cls.
  std::vector<std::unique_ptr<ClassDef>> run() {
    for (auto& d : cls_.declarations)
      if (isBodyDeclaration(d)) uses_[d.name] = BodyUse{&d, {}, {}, {}, {}};
    takeStatements();
    std::vector<std::unique_ptr<ClassDef>> generated;
    for (auto& [name, use] : uses_)
      if (auto cls = lowerBody(use)) generated.push_back(std::move(cls));
    return generated;
  }

 private:
  ClassDef& cls_;
  SourceManager& sources_;
  DiagnosticEngine& diags_;
  ConstantFolder fold_;
  std::map<std::string, BodyUse> uses_;
  std::vector<ExprPtr> gravity_;

  void error(SourceRange r, DiagCode code, std::string msg, std::string help) {
    diags_.error(r, code, std::move(msg), std::move(help));
  }

  // The body a statement's target names, or null (then the statement is not a body statement).
  BodyUse* bodyOf(const Expr* target) {
    auto* n = dyn_cast<NameExpr>(target);
    if (!n || n->parts.size() != 1) return nullptr;
    auto it = uses_.find(n->parts[0]);
    return it == uses_.end() ? nullptr : &it->second;
  }

  // Moves gravity, torque and body-force statements out of the mechanics section.
  void takeStatements() {
    std::vector<MechanicsStmt> kept;
    for (auto& st : cls_.mechanics) {
      if (!takeStatement(st)) kept.push_back(std::move(st));
    }
    cls_.mechanics = std::move(kept);
    checkNested(cls_.mechanics);
  }

  bool takeStatement(MechanicsStmt& st) {
    const char* noBody = "declare one: body b(mass = m, inertia = {A, B, C});";
    switch (st.kind) {
      case MechanicsKind::Gravity:
        if (uses_.empty())
          error(st.keywordRange, DiagCode::E0703, "gravity acts on rigid bodies, and this class declares none",
                "for coordinates write the potential energy (potential = m*g*y;); for a body " + std::string(noBody));
        else if (st.value)
          gravity_.push_back(std::move(st.value));
        return true;
      case MechanicsKind::Torque: {
        BodyUse* b = bodyOf(st.target.get());
        if (!b) {
          error(st.target ? st.target->range : st.keywordRange, DiagCode::E0703, "torque(...) names no rigid body of this class",
                uses_.empty() ? noBody : "name a body declared here, e.g. torque(" + uses_.begin()->first + ") = {0, 0, 1};");
        } else if (st.value) {
          (st.world ? b->torqueWorld : b->torqueBody).push_back(std::move(st.value));
        }
        return true;
      }
      case MechanicsKind::Force: {
        BodyUse* b = bodyOf(st.target.get());
        if (!b && st.at) {
          error(st.target ? st.target->range : st.keywordRange, DiagCode::E0703, "force(..., at = …) names no rigid body of this class",
                "'at' applies to a body; a generalized force on a coordinate is force(q) = e;");
          return true;
        }
        if (!b) return false;  // a generalized force on a coordinate
        if (st.value) b->forces.emplace_back(std::move(st.value), std::move(st.at));
        return true;
      }
      default: return false;
    }
  }

  // Body statements inside for-loops are not lowered: say so where they are.
  void checkNested(std::vector<MechanicsStmt>& list) {
    for (auto& st : list) {
      if (st.kind == MechanicsKind::For) {
        for (auto& inner : st.body)
          if (inner.kind == MechanicsKind::Gravity || inner.kind == MechanicsKind::Torque ||
              (inner.kind == MechanicsKind::Force && (inner.at || bodyOf(inner.target.get()))))
            error(inner.keywordRange, DiagCode::E0703, "a statement on a rigid body inside a for-loop",
                  "write gravity, torque and body forces outside for-loops, one statement per body");
        checkNested(st.body);
      }
    }
  }

  std::unique_ptr<ClassDef> lowerBody(BodyUse& use) {
    Declaration& d = *use.decl;
    BodyShape& s = use.shape;
    s.bodyName = d.name;
    s.className = "__body_" + cls_.name + "_" + d.name;
    if (!d.dims.empty() || !d.typeDims.empty() || d.binding || d.variability != Variability::Continuous ||
        d.causality != Causality::None || d.isCoordinate || d.isFlow) {
      error(d.nameRange, DiagCode::E0701, "a body is declared as 'body NAME(attributes);' alone",
            "remove the prefixes, array dimensions or binding; declare several bodies one by one");
      return nullptr;
    }
    std::vector<Modification> mods;
    if (!takeAttributes(d, s, mods)) return nullptr;
    addStatementModifiers(use, d, mods);
    d.mods = std::move(mods);
    d.typeName = {s.className};
    return parseGenerated(s, d.nameRange);
  }

  bool takeAttributes(Declaration& d, BodyShape& s, std::vector<Modification>& mods) {
    bool ok = true, hasMass = false, hasInertia = false;
    for (auto& m : d.mods) {
      if (m.name == "fixedPoint") {
        auto* b = dyn_cast<BoolExpr>(m.value.get());
        if (!b || !m.nested.empty()) {
          error(m.value ? m.value->range : m.nameRange, DiagCode::E0701, "fixedPoint must be written true or false",
                "it decides which equations the body has, so it cannot be a parameter");
          ok = false;
        } else {
          s.fixedPoint = b->value;
        }
      } else if (m.name == "mass" || m.name == "cm" || m.name == "inertia") {
        if (!m.value || !m.nested.empty()) {
          error(m.nameRange, DiagCode::E0701, "'" + m.name + "' needs a value", "write " + m.name + " = …");
          ok = false;
          continue;
        }
        hasMass |= m.name == "mass";
        hasInertia |= m.name == "inertia";
        s.hasCm |= m.name == "cm";
        if (m.name == "inertia") ok &= lowerInertia(m, s);
        if (m.name == "mass") ok &= checkMass(*m.value);
        mods.push_back(std::move(m));
      } else if (m.name == "q" || m.name == "omega" || m.name == "r" || m.name == "v") {
        if (m.value) {
          error(m.nameRange, DiagCode::E0701, "'" + m.name + "' is a state of the body: give its start value",
                "write " + m.name + "(start = …)");
          ok = false;
        }
        mods.push_back(std::move(m));
      } else {
        error(m.nameRange, DiagCode::E0701, "a body has no attribute '" + m.name + "'",
              "a body takes mass, inertia, cm, fixedPoint and start values of q, omega (and r, v when free)");
        ok = false;
      }
    }
    if (s.fixedPoint)
      for (const auto& m : mods)
        if (m.name == "r" || m.name == "v") {
          error(m.nameRange, DiagCode::E0701, "a body with fixedPoint = true has no '" + m.name + "'",
                "its reference point stays at the world origin; remove " + m.name + "(…)");
          ok = false;
        }
    if (ok && (!hasMass || !hasInertia))
      error(d.nameRange, DiagCode::E0701, std::string("the body '") + d.name + "' has no " + (hasMass ? "inertia" : "mass"),
            "give it: body " + d.name + "(mass = 1, inertia = {0.1, 0.1, 0.2});");
    return ok && hasMass && hasInertia;
  }

  // A mass known at compile time must be positive (a massless or negative body has no dynamics).
  bool checkMass(const Expr& value) {
    std::optional<double> mass = fold_(&value);
    if (!mass || *mass > 0) return true;
    error(value.range, DiagCode::E0701, "the mass of a body must be positive", "give its mass in kg, e.g. mass = 1");
    return false;
  }

  // `inertia = {I1, I2, I3}` (principal moments) stays `inertia`; a matrix becomes Icm.
  bool lowerInertia(Modification& m, BodyShape& s) {
    auto* arr = dyn_cast<ArrayExpr>(m.value.get());
    bool principal = arr && arr->elements.size() == 3 &&
                     std::none_of(arr->elements.begin(), arr->elements.end(), [](const ExprPtr& e) { return isa<ArrayExpr>(e.get()); });
    std::optional<Eigen::Matrix3d> known = knownInertia(m.value.get(), principal);
    if (known && !checkInertia(*known, m.value->range)) return false;
    s.principal = principal;
    if (!principal) m.name = "Icm";
    return true;
  }

  std::optional<Eigen::Matrix3d> knownInertia(const Expr* value, bool principal) const {
    auto* arr = dyn_cast<ArrayExpr>(value);
    if (!arr || arr->elements.size() != 3) return std::nullopt;
    Eigen::Matrix3d I = Eigen::Matrix3d::Zero();
    for (int i = 0; i < 3; ++i) {
      if (principal) {
        auto v = fold_(arr->elements[i].get());
        if (!v) return std::nullopt;
        I(i, i) = *v;
        continue;
      }
      auto* row = dyn_cast<ArrayExpr>(arr->elements[i].get());
      if (!row || row->elements.size() != 3) return std::nullopt;
      for (int j = 0; j < 3; ++j) {
        auto v = fold_(row->elements[j].get());
        if (!v) return std::nullopt;
        I(i, j) = *v;
      }
    }
    return I;
  }

  // A physical inertia tensor is symmetric, positive definite, and its principal moments satisfy
  // the triangle inequalities I1 + I2 ≥ I3 (and cyclic).
  bool checkInertia(const Eigen::Matrix3d& I, SourceRange where) {
    double scale = I.cwiseAbs().maxCoeff();
    const double tol = 1e-12 * scale;
    if (!(scale > 0) || !I.allFinite()) {
      error(where, DiagCode::E0702, "the inertia is zero or not finite", "give the moments of inertia in kg m²");
      return false;
    }
    if ((I - I.transpose()).cwiseAbs().maxCoeff() > tol) {
      error(where, DiagCode::E0702, "the inertia matrix is not symmetric", "an inertia tensor has Ixy = Iyx, Ixz = Izx, Iyz = Izy");
      return false;
    }
    Eigen::Vector3d m = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(I).eigenvalues();
    if (m.minCoeff() <= tol) {
      error(where, DiagCode::E0702, fmt("the inertia is not positive definite (principal moments %g, %g, %g)", m),
            "every principal moment of inertia of a body with mass is positive");
      return false;
    }
    if (m(0) + m(1) < m(2) - tol) {
      error(where, DiagCode::E0702, fmt("the principal moments %g, %g, %g violate the triangle inequality", m),
            "no body has I1 + I2 < I3: check the values (they are about the centre of mass)");
      return false;
    }
    return true;
  }

  static std::string fmt(const char* pattern, const Eigen::Vector3d& m) {
    char buf[160];
    std::snprintf(buf, sizeof buf, pattern, m(0), m(1), m(2));
    return buf;
  }

  void addStatementModifiers(BodyUse& use, const Declaration& d, std::vector<Modification>& mods) {
    BodyShape& s = use.shape;
    for (const auto& g : gravity_) mods.push_back(valueModifier("gravity", clone(*g), g->range));
    if (gravity_.size() > 1)
      error(gravity_[1]->range, DiagCode::E0701, "gravity is given twice", "state it once: gravity = {0, 0, -9.81};");
    if (!use.torqueBody.empty()) {
      s.torqueBody = true;
      mods.push_back(valueModifier("torqueBody", sumOf(use.torqueBody), d.nameRange));
    }
    if (!use.torqueWorld.empty()) {
      s.torqueWorld = true;
      mods.push_back(valueModifier("torqueWorld", sumOf(use.torqueWorld), d.nameRange));
    }
    for (auto& [force, at] : use.forces) {
      std::string k = std::to_string(++s.forces);
      SourceRange r = force->range;
      mods.push_back(valueModifier("force" + k, std::move(force), r));
      if (!at) {  // at the centre of mass: cm (or the reference point when cm is not given)
        auto zero = [&] { return std::make_unique<NumberExpr>(r, 0.0, true); };
        std::vector<ExprPtr> z;
        for (int i = 0; i < 3; ++i) z.push_back(zero());
        at = s.hasCm ? ExprPtr(std::make_unique<NameExpr>(r, std::vector<std::string>{d.name, "cm"}, std::vector<SourceRange>{r, r}))
                     : ExprPtr(std::make_unique<ArrayExpr>(r, std::move(z)));
      }
      mods.push_back(valueModifier("at" + k, std::move(at), r));
    }
  }

  std::unique_ptr<ClassDef> parseGenerated(const BodyShape& s, SourceRange where) {
    uint32_t file = sources_.addBuffer("<body " + s.bodyName + ">", bodyClassText(s));
    size_t before = diags_.errorCount();
    auto parsed = syntax::parse(sources_, file, diags_);
    if (!parsed || parsed->classes.size() != 1 || diags_.errorCount() != before) {
      error(where, DiagCode::E0701, "internal error: the class generated for this body does not parse",
            "please report this with the model");
      return nullptr;
    }
    return std::move(parsed->classes.front());
  }
};

// The generated classes go just before the class that uses them, so the file's last model (the
// one compiled by default) stays the user's.
void lowerClasses(std::vector<std::unique_ptr<ClassDef>>& classes, SourceManager& sources, DiagnosticEngine& diags) {
  std::vector<std::unique_ptr<ClassDef>> out;
  for (auto& cls : classes) {
    if (cls) {
      lowerClasses(cls->classes, sources, diags);
      for (auto& g : ClassLowering(*cls, sources, diags).run()) out.push_back(std::move(g));
    }
    out.push_back(std::move(cls));
  }
  classes = std::move(out);
}

}  // namespace

void lowerRigidBodies(StoredDefinition& file, SourceManager& sources, DiagnosticEngine& diags) {
  lowerClasses(file.classes, sources, diags);
}

}  // namespace qdot::bodies
