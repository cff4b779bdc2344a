"""Safe, vectorised math expressions for target profiles: ``y = f(x)`` and ``r = f(theta)``.

A user's text is parsed with :mod:`ast` and every node is checked against a whitelist
(numbers, the variables of the target, ``pi``, ``e``, ``+ - * / **``, unary minus and a
fixed set of functions). The accepted tree is turned into a tree of small picklable node
objects that evaluate with numpy; the text itself is never passed to ``eval`` or ``exec``.
"""

from __future__ import annotations

import ast
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pneumorph.errors import TargetExpressionError

MAX_LENGTH = 400
"""Longest expression text accepted (characters)."""
MAX_NODES = 200
"""Most syntax-tree nodes accepted."""
MAX_EXPONENT = 100.0
"""Largest absolute constant exponent accepted in ``a ** b``."""

CONSTANTS: dict[str, float] = {"pi": math.pi, "e": math.e}

FUNCTIONS: dict[str, tuple[Callable[..., Any], int, int | None]] = {
    # name: (numpy function, least number of arguments, most number of arguments)
    "sin": (np.sin, 1, 1),
    "cos": (np.cos, 1, 1),
    "tan": (np.tan, 1, 1),
    "exp": (np.exp, 1, 1),
    "log": (np.log, 1, 1),
    "sqrt": (np.sqrt, 1, 1),
    "abs": (np.abs, 1, 1),
    "min": (lambda *a: np.minimum.reduce(np.broadcast_arrays(*a)), 2, None),
    "max": (lambda *a: np.maximum.reduce(np.broadcast_arrays(*a)), 2, None),
}

_BINARY: dict[type, str] = {ast.Add: "+", ast.Sub: "-", ast.Mult: "*", ast.Div: "/", ast.Pow: "**"}
_OPERATORS: dict[str, Callable[[Any, Any], Any]] = {
    "+": np.add,
    "-": np.subtract,
    "*": np.multiply,
    "/": np.true_divide,
    "**": np.power,
}

_FORBIDDEN: dict[type, str] = {
    ast.Attribute: "attribute access is not allowed",
    ast.Subscript: "subscripts are not allowed",
    ast.Lambda: "lambda functions are not allowed",
    ast.ListComp: "comprehensions are not allowed",
    ast.SetComp: "comprehensions are not allowed",
    ast.DictComp: "comprehensions are not allowed",
    ast.GeneratorExp: "comprehensions are not allowed",
    ast.Compare: "comparisons are not allowed",
    ast.BoolOp: "boolean operators are not allowed",
    ast.IfExp: "conditional expressions are not allowed",
    ast.NamedExpr: "assignments are not allowed",
    ast.Starred: "starred arguments are not allowed",
    ast.JoinedStr: "strings are not allowed",
    ast.List: "lists are not allowed",
    ast.Tuple: "tuples are not allowed",
    ast.Dict: "dictionaries are not allowed",
    ast.Set: "sets are not allowed",
}


# -- evaluation nodes (plain, picklable) ------------------------------------------------
@dataclass(frozen=True)
class _Const:
    value: float

    def __call__(self, env: Mapping[str, Any]) -> Any:
        return self.value


@dataclass(frozen=True)
class _Var:
    name: str

    def __call__(self, env: Mapping[str, Any]) -> Any:
        return env[self.name]


@dataclass(frozen=True)
class _Neg:
    operand: Any

    def __call__(self, env: Mapping[str, Any]) -> Any:
        return np.negative(self.operand(env))


@dataclass(frozen=True)
class _Bin:
    op: str
    left: Any
    right: Any

    def __call__(self, env: Mapping[str, Any]) -> Any:
        return _OPERATORS[self.op](self.left(env), self.right(env))


@dataclass(frozen=True)
class _Call:
    name: str
    args: tuple[Any, ...]

    def __call__(self, env: Mapping[str, Any]) -> Any:
        return FUNCTIONS[self.name][0](*(a(env) for a in self.args))


@dataclass(frozen=True)
class Expression:
    """A checked expression; call it with numpy arrays for its variables.

    Attributes
    ----------
    text : str
        The expression as given.
    variables : tuple of str
        The variables it may use.
    used : frozenset of str
        The variables it does use.

    Examples
    --------
    >>> f = parse_expression("A * sin(2*pi*x/L)", variables=("x", "L", "A"))
    >>> f(x=[0.0, 25.0], L=100.0, A=10.0).round(6).tolist()
    [0.0, 10.0]
    """

    text: str
    variables: tuple[str, ...]
    used: frozenset[str]
    root: Any

    def __call__(self, **values: ArrayLike) -> NDArray[np.float64]:
        missing = sorted(self.used - set(values))
        if missing:
            raise TargetExpressionError(f"expression {self.text!r} needs a value for {', '.join(missing)}")
        env: dict[str, Any] = {k: np.asarray(v, dtype=float) for k, v in values.items()}
        env.update(CONSTANTS)
        with np.errstate(all="ignore"):
            out = self.root(env)
        given = [np.shape(env[k]) for k in self.variables if k in env]
        shape = np.broadcast_shapes(*given) if given else ()
        out = np.asarray(out, dtype=float)
        fresh = out.shape == shape and out.flags.writeable and out.flags.owndata and \
            not any(np.may_share_memory(out, env[k]) for k in self.variables if k in env)
        return out if fresh else np.broadcast_to(out, shape).copy()  # never a view of the caller's arrays


# -- checking and building --------------------------------------------------------------
def _where(text: str, node: ast.AST) -> str:
    part = ast.get_source_segment(text, node) or type(node).__name__
    col = getattr(node, "col_offset", None)
    return f"{part!r}" + (f" (column {col + 1})" if col is not None else "")


def _constant_value(node: ast.AST) -> float | None:
    """The value of a number or a signed number; None for anything else."""
    if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)) and not isinstance(node.value, bool):
        try:
            return float(node.value)
        except OverflowError:  # an integer of more than about 309 digits: too large, as 1e400 is
            return math.inf
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
        inner = _constant_value(node.operand)
        if inner is not None:
            return -inner if isinstance(node.op, ast.USub) else inner
    return None


def _contains_power(node: ast.AST) -> bool:
    return any(isinstance(n, ast.BinOp) and isinstance(n.op, ast.Pow) for n in ast.walk(node))


class _Builder:
    def __init__(self, text: str, variables: tuple[str, ...], hints: Mapping[str, str]) -> None:
        self.text = text
        self.variables = variables
        self.hints = hints
        self.used: set[str] = set()

    def fail(self, node: ast.AST, why: str) -> TargetExpressionError:
        return TargetExpressionError(f"in expression {self.text!r}: {why}: {_where(self.text, node)}")

    def build(self, node: ast.AST) -> Any:
        if type(node) in _FORBIDDEN:
            raise self.fail(node, _FORBIDDEN[type(node)])
        if isinstance(node, ast.Constant):
            value = _constant_value(node)
            if value is None:
                raise self.fail(node, "only numbers are allowed as constants")
            if not math.isfinite(value):
                raise self.fail(node, "the number is too large")
            return _Const(value)
        if isinstance(node, ast.Name):
            return self._name(node)
        if isinstance(node, ast.UnaryOp):
            if isinstance(node.op, ast.USub):
                return _Neg(self.build(node.operand))
            if isinstance(node.op, ast.UAdd):
                return self.build(node.operand)
            raise self.fail(node, "only unary minus and plus are allowed")
        if isinstance(node, ast.BinOp):
            return self._binop(node)
        if isinstance(node, ast.Call):
            return self._call(node)
        raise self.fail(node, f"{type(node).__name__} is not allowed")

    def _name(self, node: ast.Name) -> Any:
        if node.id in CONSTANTS:
            return _Var(node.id)
        if node.id in self.variables:
            self.used.add(node.id)
            return _Var(node.id)
        if node.id in FUNCTIONS:
            raise self.fail(node, f"the function {node.id} must be called with arguments, e.g. {node.id}(x)")
        allowed = ", ".join([*self.variables, *CONSTANTS])
        hint = self.hints.get(node.id, "")
        raise self.fail(node, f"unknown name {node.id!r} (allowed names: {allowed}){hint}")

    def _binop(self, node: ast.BinOp) -> Any:
        if type(node.op) not in _BINARY:
            symbol = {ast.Mod: "%", ast.FloorDiv: "//", ast.MatMult: "@", ast.BitXor: "^"}.get(type(node.op), "")
            hint = " (write powers as a ** b)" if symbol == "^" else ""
            raise self.fail(node, f"operator {symbol or type(node.op).__name__} is not allowed{hint}")
        if isinstance(node.op, ast.Pow):
            if _contains_power(node.right):
                raise self.fail(node, "exponents of exponents are not allowed")
            value = _constant_value(node.right)
            if value is not None and abs(value) > MAX_EXPONENT:
                raise self.fail(node, f"the exponent {value:g} is larger than {MAX_EXPONENT:g} in magnitude")
        return _Bin(_BINARY[type(node.op)], self.build(node.left), self.build(node.right))

    def _call(self, node: ast.Call) -> Any:
        if not isinstance(node.func, ast.Name):
            raise self.fail(node.func, "only the listed functions can be called")
        name = node.func.id
        if name not in FUNCTIONS:
            raise self.fail(node.func, f"unknown function {name!r} (allowed functions: {', '.join(FUNCTIONS)})")
        if node.keywords:
            raise self.fail(node.keywords[0].value, f"keyword arguments are not allowed in {name}()")
        _, least, most = FUNCTIONS[name]
        n = len(node.args)
        if n < least or (most is not None and n > most):
            want = f"{least}" if least == most else f"at least {least}"
            raise self.fail(node, f"{name}() takes {want} argument{'s' if want != '1' else ''}, got {n}")
        return _Call(name, tuple(self.build(a) for a in node.args))


def parse_expression(
    text: str, variables: tuple[str, ...] = ("x", "L", "A"), hints: Mapping[str, str] | None = None
) -> Expression:
    """Check a math expression against the whitelist and compile it for numpy.

    Parameters
    ----------
    text : str
        The expression, e.g. ``"A*sin(2*pi*x/L)"``.
    variables : tuple of str
        The names it may use besides ``pi`` and ``e``.
    hints : mapping, optional
        Extra text appended to the message when a given unknown name is used.

    Returns
    -------
    Expression

    Raises
    ------
    TargetExpressionError
        Empty or too long text, a syntax error, or anything outside the whitelist; the
        message quotes the offending part.

    Examples
    --------
    >>> parse_expression("max(x, 2) ** 2")(x=[1.0, 3.0]).tolist()
    [4.0, 9.0]
    >>> parse_expression("x.__class__")
    Traceback (most recent call last):
    ...
    pneumorph.errors.TargetExpressionError: in expression 'x.__class__': attribute access is not allowed:
    'x.__class__' (column 1)
    """
    if not isinstance(text, str) or not text.strip():
        raise TargetExpressionError("the target expression is empty; give e.g. 'A*sin(2*pi*x/L)'")
    text = text.strip()
    if len(text) > MAX_LENGTH:
        raise TargetExpressionError(
            f"the target expression has {len(text)} characters; at most {MAX_LENGTH} are accepted"
        )
    try:
        tree = ast.parse(text, mode="eval")
    except SyntaxError as exc:
        col = f" at column {exc.offset}" if exc.offset else ""
        raise TargetExpressionError(f"expression {text!r} is not valid syntax{col}: {exc.msg}") from None
    except (RecursionError, MemoryError, ValueError):
        raise TargetExpressionError(f"expression {text!r} is nested too deeply") from None
    n_nodes = sum(1 for _ in ast.walk(tree.body))
    if n_nodes > MAX_NODES:
        raise TargetExpressionError(
            f"expression {text!r} has {n_nodes} syntax nodes; at most {MAX_NODES} are accepted"
        )
    builder = _Builder(text, tuple(variables), hints or {})
    root = builder.build(tree.body)
    return Expression(text, tuple(variables), frozenset(builder.used), root)
