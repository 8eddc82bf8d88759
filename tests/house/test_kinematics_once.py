"""The house rule of issue 32, checked on the source: each family's kinematics is written
once. Every robot family that compiles gives its chain (``chain_data()``) and the one
forward kinematics, :func:`plannerlab.collision.kinematics.chain_frames`, composes its
joint transforms for every compiled consumer (the state test, the sphere field, the IK).
A second compiled forward kinematics is found as a compiled kernel that takes the sine and
cosine of a value inside a loop (a joint's turn composed per joint, ``math.sin`` and
``math.cos``, or ``sincos``). Not seen by it: a kinematics written without trig in its
loop (precomputed sines, say); the numpy reference kinematics of each family
(``robots/*/model.py``) is not compiled code and is not counted."""

from __future__ import annotations

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[2] / "plannerlab"

#: the one compiled forward kinematics ("module path:function")
THE_KINEMATICS = {"collision/kinematics.py:chain_frames"}


def _is_kernel(node: ast.FunctionDef) -> bool:
    for dec in node.decorator_list:
        f = dec.func if isinstance(dec, ast.Call) else dec
        name = f.attr if isinstance(f, ast.Attribute) else getattr(f, "id", "")
        if name in ("njit", "jit", "kernel", "inline_kernel"):
            return True
    return False


def _turns_in_a_loop(fn: ast.FunctionDef) -> bool:
    """Sine and cosine (or ``sincos``) called inside one loop of the function."""
    for loop in ast.walk(fn):
        if isinstance(loop, (ast.For, ast.While)):
            called = set()
            for n in ast.walk(loop):
                if isinstance(n, ast.Call):
                    f = n.func
                    called.add(f.attr if isinstance(f, ast.Attribute) else getattr(f, "id", ""))
            if {"sin", "cos"} <= called or "sincos" in called:
                return True
    return False


def kinematics_in(source: str) -> list[str]:
    """The compiled kernels of one module's source that compose joint turns."""
    return [
        node.name
        for node in ast.walk(ast.parse(source))
        if isinstance(node, ast.FunctionDef) and _is_kernel(node) and _turns_in_a_loop(node)
    ]


def test_the_counter_finds_a_kinematics_written_again():
    src = (
        "import math\nfrom numba import njit\nfrom plannerlab.collision.simd import kernel\n"
        "@njit(cache=True)\ndef frames(q, B):\n"
        "    for i in range(q.shape[0]):\n"
        "        c, s = math.cos(q[i]), math.sin(q[i])\n"
        "        B[i + 1] = B[i] * c - s\n"
        "@kernel\ndef lanes(V, F):\n"
        "    for i in range(4):\n"
        "        s, c = sincos(V[i])\n"
        "@njit\ndef once(x):\n"
        "    return math.sin(x), math.cos(x)\n"
        "def numpy_frames(q):\n"
        "    for v in q:\n"
        "        print(math.sin(v), math.cos(v))\n"
    )
    assert kinematics_in(src) == ["frames", "lanes"]


def test_each_familys_kinematics_is_written_once():
    """The package's compiled kernels compose joint turns in one place only."""
    found = set()
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE).as_posix()
        found |= {f"{rel}:{name}" for name in kinematics_in(path.read_text())}
    assert found == THE_KINEMATICS
