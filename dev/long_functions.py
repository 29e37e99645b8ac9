"""List the functions under src/armtransfer longer than a limit (default 100 lines).

    python dev/long_functions.py [LIMIT]

A function's length runs from its ``def`` (decorators excluded) to its last line; a function
nested in another is listed on its own and counted in its parent too. Jitted functions
(``@numba.njit``/``@njit``) are marked, since the numba kernels are allowed to be long.
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src" / "armtransfer"


def long_functions(limit: int) -> list[tuple[int, str, bool]]:
    """(lines, path:qualified name, jitted) of every function over ``limit`` lines."""
    found = []
    for path in sorted(SRC.rglob("*.py")):
        tree = ast.parse(path.read_text())

        def visit(node: ast.AST, prefix: str) -> None:
            for child in ast.iter_child_nodes(node):
                if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)):
                    lines = (child.end_lineno or child.lineno) - child.lineno + 1
                    jitted = any("njit" in ast.unparse(d) or "jit" in ast.unparse(d) for d in child.decorator_list)
                    if lines > limit:
                        found.append((lines, f"{path.relative_to(SRC.parent)}:{prefix}{child.name}", jitted))
                    visit(child, f"{prefix}{child.name}.")
                elif isinstance(child, ast.ClassDef):
                    visit(child, f"{prefix}{child.name}.")
                else:
                    visit(child, prefix)

        visit(tree, "")
    return sorted(found, reverse=True)


if __name__ == "__main__":
    limit = int(sys.argv[1]) if len(sys.argv) > 1 else 100
    for lines, name, jitted in long_functions(limit):
        print(f"{lines:5d}  {name}{'  (jitted)' if jitted else ''}")
