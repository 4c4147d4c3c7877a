"""Every tolerance below 1e-8 in the tests names the bound that justifies it.

The convention (``tests/roundoff.py``, docs/accuracy.md): a tolerance literal below
:data:`THRESHOLD` carries a comment containing ``bound:`` on its own line or on one of the
:data:`LINES_ABOVE` lines above, followed by the solver tolerance or round-off bound it
rests on, e.g. ``# bound: eigsh tol 1e-12 on λ -> rel. error in f <= 1e-11``. A tolerance
below what the computation guarantees fails on another BLAS kernel, thread count or
machine (a shell test compared frequencies to 1e-9 where the round-off of its thin-plate
pencil is 3e-9).

Parses every test file with :mod:`ast` (literals) and :mod:`tokenize` (comments). A
*tolerance literal* is a number ``0 < x < 1e-8`` (``1e-9``, ``1.0e-10``, ``10**-9``,
also inside an expression such as ``1e-12 * scale``) in

* a keyword argument ``rtol``, ``atol``, ``rel``, ``abs`` or ``tol`` of any call;
* the positional tolerance arguments of ``assert_allclose``, ``allclose``, ``isclose``
  (third and fourth) and ``approx`` (second and third);
* an operand of an order comparison (``err < 1e-10``, ``x > -1e-12``).
"""

from __future__ import annotations

import ast
import io
import tokenize
from pathlib import Path

TESTS = Path(__file__).resolve().parent
THRESHOLD = 1e-8
LINES_ABOVE = 3
MARK = "bound:"
KEYWORDS = frozenset({"rtol", "atol", "rel", "abs", "tol"})
POSITIONAL = {"assert_allclose": (2, 3), "allclose": (2, 3), "isclose": (2, 3),
              "approx": (1, 2)}
"""Function name: indices of its positional tolerance arguments."""
ORDER = (ast.Lt, ast.LtE, ast.Gt, ast.GtE)


def _value(node):
    """The number a literal stands for (``1e-9``, ``10**-9``, ``10.0**-9``), or None."""
    if isinstance(node, ast.Constant):
        v = node.value
        return v if isinstance(v, int | float) and not isinstance(v, bool) else None
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Pow):
        base, exp = _value(node.left), node.right
        if isinstance(exp, ast.UnaryOp) and isinstance(exp.op, ast.USub):
            e = _value(exp.operand)
            if base is not None and e is not None and base > 0:
                try:
                    return float(base) ** -float(e)
                except OverflowError:
                    return None
    return None


def small_literals(node) -> list[int]:
    """Lines of the literals ``0 < x < THRESHOLD`` in the expression ``node``."""
    return sorted({n.lineno for n in ast.walk(node)
                   if (v := _value(n)) is not None and 0 < v < THRESHOLD})


def _name(func) -> str:
    if isinstance(func, ast.Attribute):
        return func.attr
    return func.id if isinstance(func, ast.Name) else ""


def tolerance_lines(tree) -> list[int]:
    """Lines of every tolerance literal below :data:`THRESHOLD` (module docstring)."""
    lines = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Call):
            for kw in node.keywords:
                if kw.arg in KEYWORDS:
                    lines += small_literals(kw.value)
            first, last = POSITIONAL.get(_name(node.func), (0, -1))
            for arg in node.args[first:last + 1]:
                lines += small_literals(arg)
        elif isinstance(node, ast.Compare) and any(isinstance(op, ORDER) for op in node.ops):
            for operand in (node.left, *node.comparators):
                lines += small_literals(operand)
    return sorted(set(lines))


def bound_lines(source: str) -> set[int]:
    """Lines with a comment containing :data:`MARK`."""
    tokens = tokenize.generate_tokens(io.StringIO(source).readline)
    return {tok.start[0] for tok in tokens
            if tok.type == tokenize.COMMENT and MARK in tok.string}


def unbounded(source: str) -> list[int]:
    """Lines of tolerance literals without a ``bound:`` comment on them or just above."""
    marked = bound_lines(source)
    return [line for line in tolerance_lines(ast.parse(source))
            if not marked.intersection(range(line - LINES_ABOVE, line + 1))]


def test_the_checker_finds_what_it_should():
    src = "\n".join([
        "assert_allclose(a, b, rtol=1e-9)",            # 1 keyword
        "assert_allclose(a, b, 1.0e-10)",              # 2 positional rtol
        "assert np.isclose(a, b, 0, 10**-9)",          # 3 positional atol, 10**-9
        "assert x == pytest.approx(1, abs=1e-12 * s)",  # 4 inside an expression
        "assert err < 1e-10",                          # 5 comparison
        "assert err > -1e-12",                         # 6 lower bound
        "# bound: eps n for n = 4 sums of O(1)",
        "",
        "",
        "assert_allclose(a, b, atol=1e-14)",           # 10 covered by line 7
        "assert_allclose(a, b, atol=1e-14)",           # 11 line 7 is 4 above: not covered
        "assert_allclose(a, b, rtol=1e-8, atol=0)",    # 12 not below 1e-8
        "assert_allclose(a, b, rtol=1e-9)  # bound: same line",  # 13 covered
        "f(x, 1e-12)",                                 # 14 not a tolerance argument
        "",
        "s = '# bound: in a string'",                  # 16 a string is no comment
        "assert_allclose(a, b, rtol=1e-9)",            # 17 not covered by 16
    ])
    assert unbounded(src) == [1, 2, 3, 4, 5, 6, 11, 17]


def _sites():
    """(path relative to tests/, line number, source line) of every unbounded tolerance."""
    for path in sorted(TESTS.rglob("*.py")):
        source = path.read_text(encoding="utf-8")
        text = source.splitlines()
        for line in unbounded(source):
            yield path.relative_to(TESTS).as_posix(), line, text[line - 1].strip()


def test_every_tight_tolerance_names_its_bound():
    missing = [f"tests/{rel}:{line}: {code}" for rel, line, code in _sites()]
    assert not missing, (
        f"{len(missing)} tolerance(s) below {THRESHOLD:g} without a '# {MARK} ...' comment on"
        f" the line or the {LINES_ABOVE} lines above (the solver tolerance or round-off bound"
        " that justifies it; else loosen to >= 1e-8):\n" + "\n".join(missing))


if __name__ == "__main__":
    for rel, line, code in _sites():  # the unbounded sites, as the test names them
        print(f"tests/{rel}:{line}: {code}")
