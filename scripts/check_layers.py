#!/usr/bin/env python3
"""Checks the module layering declared in CMakeLists.txt against the #include lines of the tree.

The module DAG is read from the hm_module(NAME DIR DEPS ... PRIVATE_DEPS ...), hm_app(NAME DIR DEPS ...)
and hm_python(NAME DIR DEPS ...) calls of the top-level CMakeLists.txt. A file belongs to the module whose DIR is the longest prefix
of its path. The check fails (exit 1, one line per problem) when:
  - a module's file includes a header of a module it does not see: itself, its direct DEPS and
    PRIVATE_DEPS, and the DEPS (public, transitively) of those: exactly what the per-module include
    directories let the compiler see;
  - a module depends on a module declared after it (the list in CMakeLists.txt is the layer order);
  - a header includes a module or a third-party library the module links PRIVATE (dependants could not
    compile it), or a DEPS entry is used by no header (it belongs in PRIVATE_DEPS);
  - a declared dependency is used by no file of the module (a declared dependency that nothing uses),
    or a file includes a known third-party library its module does not declare.
Third-party libraries are recognised by their include prefixes (THIRD_PARTY below); a target this script
does not know is not checked. Docs: docs/architecture.md ("Layers").

Usage: check_layers.py [ROOT]      check the tree at ROOT (default: the repository of this script)
       check_layers.py --self-test  run the checker on small fixture trees, one passing, each other failing
"""
import os
import re
import sys
import tempfile

# CMake target -> regular expression on the include name (#include <NAME>) that means "uses it".
THIRD_PARTY = {
    "yaml-cpp": r"yaml-cpp/",
    "nlohmann_json::nlohmann_json": r"nlohmann/",
    "CGAL::CGAL": r"CGAL/",
    "OpenMeshCore": r"OpenMesh/",
    "Boost::graph": r"boost/graph/",
    "Eigen3::Eigen": r"(unsupported/)?Eigen/",
    "Threads::Threads": r"(thread|future|mutex|condition_variable|shared_mutex|stop_token|latch|barrier|semaphore)$",
    "TBB::tbb": r"(oneapi/)?tbb/",
    "ZLIB::ZLIB": r"zlib\.h$",
    "hm_opm_common": r"opm/",  # libopmcommon (CMakeLists.txt wraps the library in this INTERFACE target)
    "pybind11::module": r"pybind11/",
    "pybind11::headers": r"pybind11/",
    "X11::X11": r"X11/",
}
VTK_PATTERN = r"vtk"  # VTK::<Component> targets: vtkXMLUnstructuredGridReader.h, ...

SOURCE_EXT = (".cpp", ".cc", ".hpp", ".h")
HEADER_EXT = (".hpp", ".h")
INCLUDE_RE = re.compile(r'^\s*#\s*include\s*([<"])([^>"]+)[>"]', re.M)


def third_party_pattern(target):
    if target.startswith("VTK::"):
        return VTK_PATTERN
    return THIRD_PARTY.get(target)


def parse_modules(cmake_text):
    """[(kind, name, dir, public_deps, private_deps)] in declaration order."""
    text = re.sub(r"#[^\n]*", "", cmake_text)
    out = []
    for m in re.finditer(r"\b(hm_module|hm_app|hm_python)\s*\(([^)]*)\)", text):
        if re.match(r"\s*name\s+dir\b", m.group(2)):
            continue  # the function(hm_module name dir) definitions themselves
        tokens = m.group(2).split()
        kind, name, folder = m.group(1), tokens[0], tokens[1].rstrip("/")
        public, private, mode = [], [], None
        for t in tokens[2:]:
            if t in ("DEPS", "PRIVATE_DEPS"):
                mode = t
            elif "$" in t:
                continue  # variables and generator expressions are not checked
            elif mode == "DEPS":
                (public if kind == "hm_module" else private).append(t)
            elif mode == "PRIVATE_DEPS":
                private.append(t)
        out.append((kind, name, folder, public, private))
    return out


def owner_of(path, modules):
    """Module (or app) whose folder is the longest prefix of path, else None."""
    best = None
    for mod in modules:
        folder = mod[2]
        if path == folder or path.startswith(folder + "/"):
            if best is None or len(folder) > len(best[2]):
                best = mod
    return best


def scan(root, modules):
    """{module name: [(file relative path, is_header, [(kind, include name, resolved relative path)])]}"""
    files = {m[1]: [] for m in modules}
    for mod in modules:
        base = os.path.join(root, mod[2])
        for dirpath, _, names in os.walk(base):
            for n in sorted(names):
                if not n.endswith(SOURCE_EXT):
                    continue
                full = os.path.join(dirpath, n)
                rel = os.path.relpath(full, root).replace(os.sep, "/")
                if owner_of(rel, modules) is not mod:
                    continue  # belongs to a nested module or app
                with open(full, encoding="utf-8", errors="replace") as f:
                    text = f.read()
                incs = []
                for q, name in INCLUDE_RE.findall(text):
                    resolved = None
                    if q == '"':
                        for cand in (os.path.join(dirpath, name), os.path.join(root, name)):
                            if os.path.isfile(cand):
                                resolved = os.path.relpath(os.path.realpath(cand), os.path.realpath(root))
                                resolved = resolved.replace(os.sep, "/")
                                break
                    incs.append((q, name, resolved))
                files[mod[1]].append((rel, n.endswith(HEADER_EXT), incs))
    return files


def check(root):
    """List of problems (empty: the layering holds)."""
    with open(os.path.join(root, "CMakeLists.txt"), encoding="utf-8") as f:
        modules = parse_modules(f.read())
    problems = []
    by_name = {m[1]: m for m in modules}
    order = {m[1]: i for i, m in enumerate(modules)}
    libs = {m[1] for m in modules if m[0] == "hm_module"}

    for kind, name, _, public, private in modules:
        for d in public + private:
            if d in by_name and (by_name[d][0] != "hm_module" or order[d] >= order[name]):
                problems.append(f"{name}: depends on {d}, which is not a module declared before it")

    def public_closure(name, seen=None):
        seen = set() if seen is None else seen
        for d in by_name[name][3]:
            if d in libs and d not in seen:
                seen.add(d)
                public_closure(d, seen)
        return seen

    files = scan(root, modules)
    for kind, name, folder, public, private in modules:
        direct = [d for d in public + private if d in libs]
        visible = {name}
        for d in direct:
            visible.add(d)
            visible |= public_closure(d)
        header_visible = {name}
        for d in public:
            if d in libs:
                header_visible.add(d)
                header_visible |= public_closure(d)
        used_by_any, used_by_header = set(), set()
        for rel, is_header, incs in files[name]:
            for q, inc, resolved in incs:
                if q == '"' and resolved is not None:
                    other = owner_of(resolved, modules)
                    if other is None:
                        problems.append(f"{rel}: includes {inc}, which belongs to no library module")
                        continue
                    o = other[1]
                    if o == name:
                        continue
                    used_by_any.add(o)
                    if is_header:
                        used_by_header.add(o)
                    if o not in libs:
                        problems.append(f"{rel}: includes {inc} of {o}, which is not a library")
                    elif o not in visible:
                        problems.append(f"{rel}: includes {inc} of {o}, which {name} does not depend on "
                                        f"(it sees {', '.join(sorted(visible))})")
                    elif is_header and kind == "hm_module" and o not in header_visible:
                        problems.append(f"{rel}: header includes {inc} of {o}, a PRIVATE dependency of {name} "
                                        f"(move it to DEPS)")
                elif q == "<":
                    for t in set(public + private) | set(THIRD_PARTY):
                        pat = third_party_pattern(t)
                        if pat and re.match(pat, inc):
                            if t not in public + private:
                                if t in THIRD_PARTY and not any(third_party_pattern(x) == pat for x in public + private):
                                    problems.append(f"{rel}: includes <{inc}> but {name} does not declare {t}")
                                continue
                            used_by_any.add(t)
                            if is_header:
                                used_by_header.add(t)
                                if kind == "hm_module" and t not in public:
                                    problems.append(f"{rel}: header includes <{inc}> of {t}, a PRIVATE dependency "
                                                    f"of {name} (move it to DEPS)")
        for d in public + private:
            known = d in libs or third_party_pattern(d) is not None
            if known and d not in used_by_any:
                problems.append(f"{name}: declares {d} but no file in {folder}/ uses it")
            elif known and kind == "hm_module" and d in public and d not in used_by_header:
                problems.append(f"{name}: {d} is in DEPS but only its .cpp files use it (move it to PRIVATE_DEPS)")
    return problems


FIXTURE_CMAKE = """
function(hm_module name dir)
endfunction()
hm_module(lo  a/lo)
hm_module(mid a/mid DEPS lo PRIVATE_DEPS yaml-cpp)
hm_module(hi  a/hi  DEPS mid)   # a comment with hm_module(x y) in it is ignored
hm_app(app a/app DEPS hi)
"""
FIXTURE_FILES = {
    "a/lo/lo.hpp": "#pragma once\nstruct Lo {};\n",
    "a/lo/lo.cpp": '#include "lo.hpp"\n',
    "a/mid/mid.hpp": '#pragma once\n#include "a/lo/lo.hpp"\nstruct Mid { Lo lo; };\n',
    "a/mid/mid.cpp": '#include "a/mid/mid.hpp"\n#include <yaml-cpp/yaml.h>\n#include <vector>\n',
    "a/hi/hi.hpp": '#pragma once\n#include "a/mid/mid.hpp"\n',
    "a/hi/hi.cpp": '#include "hi.hpp"\n#include "a/lo/lo.hpp"\n',
    "a/app/main.cpp": '#include "a/hi/hi.hpp"\n#include "a/mid/mid.hpp"\n',
}
# (what the mutation does, {file: new text} or a CMake replacement, expected problem text)
FIXTURE_FAILURES = [
    ("upward include", {"a/lo/lo.cpp": '#include "a/mid/mid.hpp"\n'}, "lo does not depend on"),
    ("private third-party library in a header", {"a/mid/mid.hpp": "#pragma once\n#include <yaml-cpp/yaml.h>\n"
                                                 '#include "a/lo/lo.hpp"\n'}, "a PRIVATE dependency of mid"),
    ("undeclared third-party library", {"a/hi/hi.cpp": '#include "hi.hpp"\n#include "a/lo/lo.hpp"\n'
                                        "#include <CGAL/Origin.h>\n"}, "does not declare CGAL::CGAL"),
    ("unused declared module", ("hm_module(hi  a/hi  DEPS mid)", "hm_module(hi  a/hi  DEPS mid lo)"),
     "hi: lo is in DEPS but only"),
    ("unused declared library", ("PRIVATE_DEPS yaml-cpp", "PRIVATE_DEPS yaml-cpp nlohmann_json::nlohmann_json"),
     "declares nlohmann_json::nlohmann_json but no file"),
    ("public dependency only the .cpp files use", {"a/mid/mid.hpp": "#pragma once\n",
                                                   "a/mid/mid.cpp": '#include "a/lo/lo.hpp"\n#include <yaml-cpp/yaml.h>\n'},
     "mid: lo is in DEPS but only its .cpp files use it"),
    ("module not seen through a PRIVATE dependency", ("hm_module(hi  a/hi  DEPS mid)",
                                                      "hm_module(hi  a/hi  PRIVATE_DEPS mid)"),
     "app/main.cpp: includes a/mid/mid.hpp of mid, which app does not depend on"),
    ("dependency on a later module", ("hm_module(lo  a/lo)", "hm_module(lo  a/lo DEPS hi)"),
     "lo: depends on hi, which is not a module declared before it"),
    ("include of a file outside every module", {"a/hi/hi.cpp": '#include "tests/helper.hpp"\n#include "a/lo/lo.hpp"\n',
                                                "tests/helper.hpp": "#pragma once\n"}, "belongs to no library module"),
]


def write_fixture(root, cmake, files):
    with open(os.path.join(root, "CMakeLists.txt"), "w") as f:
        f.write(cmake)
    for rel, text in files.items():
        os.makedirs(os.path.dirname(os.path.join(root, rel)), exist_ok=True)
        with open(os.path.join(root, rel), "w") as f:
            f.write(text)


def self_test():
    failures = 0
    with tempfile.TemporaryDirectory() as tmp:
        base = os.path.join(tmp, "pass")
        os.makedirs(base)
        write_fixture(base, FIXTURE_CMAKE, FIXTURE_FILES)
        problems = check(base)
        if problems:
            failures += 1
            print("self-test FAILED: the layered fixture reports problems:\n  " + "\n  ".join(problems))
        else:
            print("self-test: layered fixture passes")
        for i, (what, change, expected) in enumerate(FIXTURE_FAILURES):
            d = os.path.join(tmp, f"fail{i}")
            os.makedirs(d)
            cmake, files = FIXTURE_CMAKE, dict(FIXTURE_FILES)
            if isinstance(change, tuple):
                assert change[0] in cmake
                cmake = cmake.replace(change[0], change[1])
            else:
                files.update(change)
            write_fixture(d, cmake, files)
            problems = check(d)
            if any(expected in p for p in problems):
                print(f"self-test: {what}: fails as it must")
            else:
                failures += 1
                print(f"self-test FAILED: {what}: expected a problem containing '{expected}', got {problems}")
    return failures


def main(argv):
    if len(argv) > 1 and argv[1] == "--self-test":
        return 1 if self_test() else 0
    root = argv[1] if len(argv) > 1 else os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
    problems = check(root)
    for p in problems:
        print("check_layers: " + p)
    if problems:
        print(f"check_layers: {len(problems)} problem(s); the layers are declared in CMakeLists.txt (hm_module DEPS / "
              "PRIVATE_DEPS), docs/architecture.md")
        return 1
    print("check_layers: every include respects the module DAG in CMakeLists.txt")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
