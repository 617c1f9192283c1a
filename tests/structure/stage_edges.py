#!/usr/bin/env python3
"""Each stage's README says which stages it may use, in one line:

    **May use:** kernel, support (and LLVM 16)

This test checks that line against the stage's CMake link edges (the qdot_* libraries its
qdot_stage(... DEPS ...) call or target_link_libraries name), for every folder under compiler/
and runtime/, and against the "may use" column of compiler/README.md's pipeline table. Names
outside the project's own libraries (fmt, LLVM 16, SUNDIALS ...) may be mentioned in
parentheses and are not compared. Usage: stage_edges.py SOURCE_DIR
"""
import pathlib
import re
import sys

root = pathlib.Path(sys.argv[1])
failures = []

# compiler/<folder> builds qdot_<target> (the driver's library is qdot_pipeline); runtime/<folder>
# sources go into qdot_runtime (ida, sim, output), qdot_vm (vm) or qdot_exe_main (exe).
TARGET_OF_FOLDER = {"driver": "pipeline"}
RUNTIME_TARGETS = {"ida": "runtime", "sim": "runtime", "output": "runtime", "vm": "vm", "exe": "exe_main"}


def cmake_edges(folder: pathlib.Path):
    """The qdot_* libraries linked by the stage library defined in folder/CMakeLists.txt."""
    text = (folder / "CMakeLists.txt").read_text()
    target = TARGET_OF_FOLDER.get(folder.name, folder.name)
    m = re.search(r"qdot_stage\(\s*" + re.escape(target) + r"\b(.*?)\)", text, re.S)
    if not m:
        return None
    deps = m.group(1).split("DEPS", 1)[1] if "DEPS" in m.group(1) else ""
    links = re.findall(r"target_link_libraries\(\s*qdot_" + re.escape(target) + r"\b(.*?)\)", text, re.S)
    words = re.findall(r"\bqdot_(\w+)", deps + " ".join(links))
    return {folder_name(w) for w in words}


def folder_name(target: str) -> str:
    for folder, t in TARGET_OF_FOLDER.items():
        if t == target:
            return folder
    return target


def readme_edges(readme: pathlib.Path, known):
    lines = [l for l in readme.read_text().splitlines() if l.startswith("**May use:**")]
    if len(lines) != 1:
        failures.append(f"{readme.relative_to(root)}: needs exactly one line starting with '**May use:**' (has {len(lines)})")
        return None
    listed = re.sub(r"\(.*?\)", "", lines[0][len("**May use:**"):])
    names = {w.strip(" .`/") for w in listed.split(",")}
    unknown = {n for n in names if n and n not in known and n != "—"}
    if unknown:
        failures.append(f"{readme.relative_to(root)}: 'May use' names {sorted(unknown)}, which are not stages")
    return {n for n in names if n in known}


compiler = root / "compiler"
stages = sorted(p for p in compiler.iterdir() if (p / "CMakeLists.txt").exists())
known = {p.name for p in stages} | {"pipeline", "vm", "runtime"}
table = {}
for line in (compiler / "README.md").read_text().splitlines():
    cells = [c.strip() for c in line.strip().strip("|").split("|")]
    if len(cells) >= 5 and re.fullmatch(r"`\w+/`", cells[0]):
        table[cells[0].strip("`/")] = {w.strip(" `") for w in re.sub(r"\(.*?\)", "", cells[-1]).split(",")} & known

for folder in stages:
    edges = cmake_edges(folder)
    if edges is None:
        failures.append(f"compiler/{folder.name}/CMakeLists.txt: no qdot_stage() call")
        continue
    said = readme_edges(folder / "README.md", known)
    if said is not None and said != edges:
        failures.append(f"compiler/{folder.name}/README.md says it may use {sorted(said)}, "
                        f"but CMake links {sorted(edges)}")
    if folder.name not in table:
        failures.append(f"compiler/README.md: the pipeline table has no row for {folder.name}/")
    elif table[folder.name] != edges:
        failures.append(f"compiler/README.md: the row of {folder.name}/ says {sorted(table[folder.name])}, "
                        f"but CMake links {sorted(edges)}")

for f in failures:
    print("FAIL", f)
print(f"stage_edges: {len(stages)} stages checked, {len(failures)} problems")
sys.exit(1 if failures else 0)
