"""Count the imports written inside function bodies under src/armtransfer, by package.

    python dev/local_imports.py            # counts per package and the total
    python dev/local_imports.py --list     # every one, as path:line: module (and its comment)
    python dev/local_imports.py --bare     # those with no comment beside them or heading their run

A lazy import is kept only for an optional extra or for start-up time, with a comment that
says so; this lists them so a reviewer can check each one has its reason.
"""

from __future__ import annotations

import ast
import sys
from collections import Counter
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src" / "armtransfer"


def local_imports(path: Path) -> list[tuple[int, str]]:
    """(line, module) of every Import/ImportFrom inside a function body of ``path``."""
    tree = ast.parse(path.read_text())
    found: list[tuple[int, str]] = []

    def visit(node: ast.AST, in_function: bool) -> None:
        for child in ast.iter_child_nodes(node):
            inside = in_function or isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda))
            if in_function and isinstance(child, ast.Import):
                found.append((child.lineno, ", ".join(a.name for a in child.names)))
            elif in_function and isinstance(child, ast.ImportFrom):
                found.append((child.lineno, "." * child.level + (child.module or "")))
            visit(child, inside)

    visit(tree, False)
    return found


def package_of(path: Path) -> str:
    rel = path.relative_to(SRC)
    return rel.parts[0] if len(rel.parts) > 1 else "(top level)"


def main(argv: list[str]) -> None:
    counts: Counter[str] = Counter()
    for path in sorted(SRC.rglob("*.py")):
        hits = local_imports(path)
        counts[package_of(path)] += len(hits)
        lines = path.read_text().splitlines()
        for line, module in hits:
            above = line - 2  # a comment may head a run of imports
            while above >= 0 and lines[above].strip().startswith(("import ", "from ")):
                above -= 1
            said = "#" in lines[line - 1] or (above >= 0 and lines[above].strip().startswith("#"))
            if "--list" in argv or ("--bare" in argv and not said):
                print(f"{path.relative_to(SRC.parent)}:{line}: {module}  | {lines[line - 1].strip()}")
    for package, n in counts.most_common():
        print(f"{n:5d}  {package}")
    print(f"{sum(counts.values()):5d}  total")


if __name__ == "__main__":
    main(sys.argv[1:])
