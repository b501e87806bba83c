#!/usr/bin/env python3
"""Every file the code and the documentation cite is in the repository, and no source file is
over the size limit.

Usage: citations.py ROOT [MAX_LINES]
Reads the comments of the C++ sources, scripts and CMake files under engine/, reference/,
comparisons/, tests/, examples/, python/ and scenes/ (a path in a string literal is a program's input, not a
citation), and the Markdown files at the top and under docs/. A citation is a path that
starts at one of the repository's top folders ("engine/world.h", "docs/style.md:12") or a
Markdown file named in capitals (such as the README); each must name a file or folder of the
repository. Generated files (under a build folder, reports/latest/, the cache) are not
citations and are skipped by their folder names. Exits 1 naming every broken citation, and every
C++ source over MAX_LINES lines (default 900).
"""
import glob
import os
import re
import sys

TOP = ("engine", "reference", "comparisons", "tests", "docs", "scenes", "reports", "examples",
       "python")
# Paths the program writes or the user supplies, named in the text as such, not files of ours.
GENERATED = ("reports/latest", "reports/perf.md", "reports/explore", "build", "scenes/x.toml")
CITATION = re.compile(r"(?<![\w./-])((?:%s)/[\w./-]*[\w])" % "|".join(TOP))
CAPITAL_MD = re.compile(r"(?<![\w/.-])([A-Z][A-Z_]+\.md)\b")


def sources(root):
    """The files read, relative to root."""
    patterns = []
    for top in ("engine", "reference", "comparisons", "tests", "examples", "python"):
        for ext in ("h", "cpp", "py", "sh", "js", "txt", "toml"):
            patterns.append(f"{top}/**/*.{ext}")
    patterns += ["*.md", "docs/*.md", "rbx", ".ci/run", "CMakeLists.txt", "scenes/**/*.toml",
                 "scenes/**/*.md", "python/**/*.py", "python/**/*.cpp", "python/CMakeLists.txt"]
    found = set()
    for p in patterns:
        found.update(glob.glob(os.path.join(root, p), recursive=True))
    return sorted(os.path.relpath(f, root) for f in found if "/build" not in f)


def cited_text(rel, line, in_block):
    """The part of `line` that is prose: its comment in code (C++ // and /* */, # in scripts),
    all of it in Markdown. Returns (text, still inside a /* */ block)."""
    if rel.endswith(".md"):
        return line, False
    if rel.endswith((".h", ".cpp", ".js")):
        text = ""
        if in_block:
            end = line.find("*/")
            if end < 0:
                return line, True
            text, line = line[:end], line[end + 2:]
        start = line.find("/*")
        if start >= 0 and "*/" not in line[start:]:
            return text + line[start:], True
        slash = line.find("//")
        return text + (line[slash:] if slash >= 0 else ""), False
    hash_at = line.find("#")
    return (line[hash_at:] if hash_at >= 0 else ""), False


def exists(root, cited):
    """Whether `cited` (a path, perhaps with :line, a trailing dot or a glob) names something."""
    path = cited.split(":")[0].rstrip(".")
    if any(path.startswith(g) for g in GENERATED):
        return True
    if any(c in path for c in "*<>{"):
        return True
    return os.path.exists(os.path.join(root, path)) or bool(glob.glob(os.path.join(root, path + "*")))


def main():
    root = sys.argv[1]
    max_lines = int(sys.argv[2]) if len(sys.argv) > 2 else 900
    broken, long_files = [], []
    for rel in sources(root):
        with open(os.path.join(root, rel), encoding="utf-8", errors="replace") as f:
            text = f.read()
        in_block = False
        for lineno, raw in enumerate(text.split("\n"), 1):
            line, in_block = cited_text(rel, raw, in_block)
            for m in CITATION.finditer(line):
                if not exists(root, m.group(1)):
                    broken.append(f"{rel}:{lineno}: cites {m.group(1)}, not in the repository")
            for m in CAPITAL_MD.finditer(line):
                name = m.group(1)
                if not (os.path.exists(os.path.join(root, name)) or
                        os.path.exists(os.path.join(os.path.dirname(os.path.join(root, rel)), name))):
                    broken.append(f"{rel}:{lineno}: cites {name}, not in the repository")
        if rel.endswith((".h", ".cpp")) and not rel.startswith("tests/"):
            n = text.count("\n")
            if n > max_lines:
                long_files.append(f"{rel}: {n} lines (limit {max_lines})")
    for line in broken + long_files:
        print(line)
    print(f"{len(sources(root))} files read: {len(broken)} broken citations, "
          f"{len(long_files)} sources over {max_lines} lines")
    return 1 if broken or long_files else 0


if __name__ == "__main__":
    sys.exit(main())
