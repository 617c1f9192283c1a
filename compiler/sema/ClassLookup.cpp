// Class name lookup (see ClassLookup.h).
#include "sema/ClassLookup.h"

namespace qdot::sema {

using namespace qdot::ast;

ClassLookup::ClassLookup(const StoredDefinition& file, const Library& library)
    : fileImports_(file.imports), library_(library) {
  for (const auto& c : file.classes) {
    registerClass(*c, nullptr);
    fileClasses_.emplace(c->name, c.get());
  }
}

void ClassLookup::registerClass(const ClassDef& c, const ClassDef* parent) {
  parent_[&c] = parent;
  for (const auto& n : c.classes) registerClass(*n, &c);
}

std::string ClassLookup::fullName(const ClassDef* c) const {
  std::string name = c->name;
  for (auto it = parent_.find(c); it != parent_.end() && it->second; it = parent_.find(it->second))
    name = it->second->name + "." + name;
  return name;
}

const ClassDef* ClassLookup::nested(const ClassDef* c, const std::string& name) {
  for (const auto& n : c->classes)
    if (n->name == name) return n.get();
  return nullptr;
}

// The file's classes shadow the library's; a library package is loaded once, found or not.
const ClassDef* ClassLookup::topLevel(const std::string& name) {
  if (auto it = fileClasses_.find(name); it != fileClasses_.end()) return it->second;
  if (auto it = libraryClasses_.find(name); it != libraryClasses_.end()) return it->second;
  const ClassDef* found = library_.find ? library_.find(name) : nullptr;
  if (found) registerClass(*found, nullptr);
  libraryClasses_.emplace(name, found);
  return found;
}

const ClassDef* ClassLookup::resolvePath(const std::vector<std::string>& path) {
  const ClassDef* c = path.empty() ? nullptr : topLevel(path[0]);
  for (size_t i = 1; c && i < path.size(); ++i) c = nested(c, path[i]);
  return c;
}

// `import A.B.C;` and `import C = A.B.C;` name one class; `import A.B.*;` every class of A.B.
const ClassDef* ClassLookup::fromImports(const std::vector<ImportClause>& imports, const std::string& name) {
  if (importDepth_ > 16) return nullptr;
  ++importDepth_;
  const ClassDef* found = nullptr;
  for (const auto& imp : imports) {
    if (imp.path.empty()) continue;
    if (imp.wildcard) {
      std::vector<std::string> path = imp.path;
      path.push_back(name);
      found = resolvePath(path);
    } else if ((imp.alias.empty() ? imp.path.back() : imp.alias) == name) {
      found = resolvePath(imp.path);
    }
    if (found) break;
  }
  --importDepth_;
  return found;
}

const ClassDef* ClassLookup::resolve(const std::vector<std::string>& parts, const ClassDef* context) {
  if (parts.empty()) return nullptr;
  const ClassDef* first = nullptr;
  const ClassDef* outermost = context;
  for (const ClassDef* s = context; s && !first; s = parent_.count(s) ? parent_.at(s) : nullptr) {
    if (s->name == parts[0] && s != context) first = s;  // an enclosing package by its own name
    if (!first) first = nested(s, parts[0]);
    if (!first) first = fromImports(s->imports, parts[0]);
    outermost = s;
  }
  // The model file's own imports (at its top) serve its classes; a library file's do not.
  bool inModelFile = outermost && fileClasses_.count(outermost->name) && fileClasses_.at(outermost->name) == outermost;
  if (!first && inModelFile) first = fromImports(fileImports_, parts[0]);
  if (!first) first = topLevel(parts[0]);
  for (size_t i = 1; first && i < parts.size(); ++i) first = nested(first, parts[i]);
  return first;
}

}  // namespace qdot::sema
