// The library path and the loading of library packages (see LibraryPath.h).
#include "driver/LibraryPath.h"

#include <cstdlib>
#include <filesystem>

#include "bodies/RigidBodies.h"
#include "syntax/Parser.h"

namespace qdot::driver {

namespace fs = std::filesystem;

fs::path executableDirectory() {
  std::error_code ec;
  fs::path self = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::path() : self.parent_path();
}

namespace {

std::string standardLibrary() {
  std::error_code ec;
  fs::path exe = executableDirectory();
  for (const fs::path& dir : {exe / "stdlib", exe / ".." / "share" / "qdot" / "stdlib"})
    if (!exe.empty() && fs::is_directory(dir, ec)) return dir.lexically_normal().string();
  return QDOT_SOURCE_STDLIB;  // the build tree: the sources qdot was built from
}

}  // namespace

std::vector<std::string> libraryPath(const std::string& modelFile) {
  std::vector<std::string> path;
  if (const char* env = std::getenv("QDOT_PATH")) {
    std::string text = env;
    for (size_t begin = 0; begin <= text.size();) {
      size_t end = text.find(':', begin);
      if (end == std::string::npos) end = text.size();
      if (end > begin) path.push_back(text.substr(begin, end - begin));
      begin = end + 1;
    }
  }
  if (!modelFile.empty() && modelFile != "-") {
    fs::path dir = fs::path(modelFile).parent_path();
    path.push_back(dir.empty() ? "." : dir.string());
  }
  path.push_back(standardLibrary());
  return path;
}

sema::Library LibraryLoader::library() {
  std::string text;
  for (const auto& dir : path_) text += (text.empty() ? "" : ", ") + dir;
  return {[this](const std::string& name) { return find(name); }, text};
}

const ast::ClassDef* LibraryLoader::find(const std::string& name) {
  std::error_code ec;
  for (const auto& dir : path_)
    for (const fs::path& file : {fs::path(dir) / name / "package.qd", fs::path(dir) / (name + ".qd")}) {
      if (!fs::is_regular_file(file, ec)) continue;
      uint32_t id = 0;
      std::string error;
      if (!sources_.addFile(file.string(), id, error)) {
        diags_.error({}, DiagCode::E0001, error, "check the library path (QDOT_PATH)");
        return nullptr;
      }
      files_.push_back(syntax::parse(sources_, id, diags_));
      if (!files_.back()) return nullptr;
      bodies::lowerRigidBodies(*files_.back(), sources_, diags_);
      for (const auto& c : files_.back()->classes)
        if (c->name == name) return c.get();
    }
  return nullptr;
}

}  // namespace qdot::driver
