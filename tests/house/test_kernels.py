"""The house rule of issue 32, checked on the source: no compiled kernel takes more than
8 parameters (a kernel's inputs travel as named tuples of arrays, which numba loads from
its cache; jitclass instances do not cache). The kernels still over it are listed, each
with its count: the list can only shrink."""

from __future__ import annotations

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[2] / "plannerlab"

#: the most parameters a compiled kernel may take
MAX_KERNEL_PARAMETERS = 8

#: kernels still over the rule ("module path:function" -> parameters), to be cut down
STILL_OVER: dict[str, int] = {}


def _is_kernel(node: ast.FunctionDef) -> bool:
    """Compiled by numba: decorated by ``njit``/``jit`` (called or not, ``numba.`` or
    not) or by the house's ``kernel`` (``collision.simd.kernel``)."""
    for dec in node.decorator_list:
        f = dec.func if isinstance(dec, ast.Call) else dec
        name = f.attr if isinstance(f, ast.Attribute) else getattr(f, "id", "")
        if name in ("njit", "jit", "kernel"):
            return True
    return False


def _parameters(node: ast.FunctionDef) -> int:
    a = node.args
    return (
        len(a.posonlyargs)
        + len(a.args)
        + len(a.kwonlyargs)
        + (a.vararg is not None)
        + (a.kwarg is not None)
    )


def kernels_over(source: str, limit: int = MAX_KERNEL_PARAMETERS) -> dict[str, int]:
    """The kernels of one module's source taking more than ``limit`` parameters."""
    out = {}
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.FunctionDef) and _is_kernel(node):
            k = _parameters(node)
            if k > limit:
                out[node.name] = k
    return out


def _all_over() -> tuple[dict[str, int], int]:
    over, n = {}, 0
    for path in sorted(PACKAGE.rglob("*.py")):
        text = path.read_text()
        rel = path.relative_to(PACKAGE).as_posix()
        n += sum(
            isinstance(node, ast.FunctionDef) and _is_kernel(node)
            for node in ast.walk(ast.parse(text))
        )
        for name, k in kernels_over(text).items():
            over[f"{rel}:{name}"] = k
    return over, n


def test_the_counter_sees_kernels_over_the_limit():
    src = (
        "from numba import njit\nimport numba\nfrom plannerlab.collision.simd import kernel\n"
        "@njit(cache=True)\ndef a(p1, p2, p3, p4, p5, p6, p7, p8, p9): pass\n"
        "@numba.njit\ndef b(p1, p2, p3, p4, p5, p6, p7, p8, *rest): pass\n"
        "@kernel\ndef c(p1, p2, p3, p4, p5, p6, p7, p8): pass\n"
        "def d(p1, p2, p3, p4, p5, p6, p7, p8, p9): pass\n"
    )
    assert kernels_over(src) == {"a": 9, "b": 9}


def test_no_new_kernel_takes_more_than_eight_parameters():
    """Every kernel over the limit is listed with its count, and no listed one has grown;
    one cut down to the limit must come off the list (the count only goes down)."""
    over, n_kernels = _all_over()
    assert n_kernels > 100  # the counter sees the package's kernels
    assert sorted(set(over) - set(STILL_OVER)) == []
    assert {k: v for k, v in over.items() if v > STILL_OVER[k]} == {}
    assert sorted(set(STILL_OVER) - set(over)) == []  # cut down: take it off the list
    assert len(over) <= 0
