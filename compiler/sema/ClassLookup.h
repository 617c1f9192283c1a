// ClassLookup: which class a type name means where it is written (Modelica's lookup, reduced to
// what qdot has): the classes nested in the class that writes it and in each enclosing class, the
// imports of those classes, the file's top-level classes, then the library (a top-level package
// found on the library path). Internal to sema.
#pragma once

#include <string>
#include <unordered_map>
#include <vector>

#include "ast/AST.h"
#include "sema/Sema.h"

namespace qdot::sema {

class ClassLookup {
 public:
  ClassLookup(const ast::StoredDefinition& file, const Library& library);

  /// The class that `parts` (`Mass`, `Vibration.Mass`) names inside `context`, or null.
  const ast::ClassDef* resolve(const std::vector<std::string>& parts, const ast::ClassDef* context);
  /// "Vibration.Mass": the names of the enclosing classes and the class.
  std::string fullName(const ast::ClassDef* c) const;

 private:
  void registerClass(const ast::ClassDef& c, const ast::ClassDef* parent);
  const ast::ClassDef* topLevel(const std::string& name);
  const ast::ClassDef* resolvePath(const std::vector<std::string>& path);
  const ast::ClassDef* fromImports(const std::vector<ast::ImportClause>& imports, const std::string& name);
  static const ast::ClassDef* nested(const ast::ClassDef* c, const std::string& name);

  std::unordered_map<const ast::ClassDef*, const ast::ClassDef*> parent_;
  std::unordered_map<std::string, const ast::ClassDef*> fileClasses_;
  const std::vector<ast::ImportClause>& fileImports_;  ///< the model file's top-level imports
  std::unordered_map<std::string, const ast::ClassDef*> libraryClasses_;  ///< by top-level name (null: not found)
  const Library& library_;
  int importDepth_ = 0;  ///< imports resolving imports: bounded, so a cycle of imports cannot loop
};

}  // namespace qdot::sema
