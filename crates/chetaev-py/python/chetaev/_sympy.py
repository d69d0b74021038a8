"""sympy expressions as operations of chetaev's expression graph.

A sympy expression is a tree whose equal subtrees are equal objects; converting it node by node with
a table of the nodes already converted gives each distinct subexpression one operation, so the graph
keeps every shared term (what ``sympy.cse`` would find among identical subtrees) and the engine
evaluates it once. Nothing is turned into a string, and nothing is differentiated here: ``chetaev``
differentiates the graph itself.

The operations are those of ``chetaev_scene::graph`` (Rust)::

    const c | param p | t | q i | qd i | add a b ... | mul a b ... | pow a b
    sqrt cbrt exp ln log10 log2 sin cos tan asin acos atan sinh cosh tanh asinh acosh atanh abs
    atan2 y x
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Iterable, Mapping, Sequence

import sympy
from sympy.core.function import AppliedUndef

from ._chetaev import ChetaevError

_FUNCTIONS = {
    sympy.exp: "exp",
    sympy.log: "ln",
    sympy.sin: "sin",
    sympy.cos: "cos",
    sympy.tan: "tan",
    sympy.asin: "asin",
    sympy.acos: "acos",
    sympy.atan: "atan",
    sympy.sinh: "sinh",
    sympy.cosh: "cosh",
    sympy.tanh: "tanh",
    sympy.asinh: "asinh",
    sympy.acosh: "acosh",
    sympy.atanh: "atanh",
    sympy.Abs: "abs",
}

# Reciprocal functions, written with the function whose reciprocal they are.
_RECIPROCALS = {
    sympy.sec: sympy.cos,
    sympy.csc: sympy.sin,
    sympy.cot: sympy.tan,
    sympy.sech: sympy.cosh,
    sympy.csch: sympy.sinh,
    sympy.coth: sympy.tanh,
}


class ConversionError(ChetaevError):
    """A sympy expression or argument chetaev cannot take, with what to write instead."""


@dataclass
class Symbols:
    """What the names of a model's expressions stand for: time, the coordinates ``q_i(t)`` (their
    derivatives are the velocities) and the parameters."""

    t: sympy.Symbol
    q: list[Any]
    parameters: list[sympy.Symbol]
    values: list[float]
    names: list[str] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.index = {c: i for i, c in enumerate(self.q)}
        self.velocity = {c.diff(self.t): i for i, c in enumerate(self.q)}
        self.parameter_index = {p: i for i, p in enumerate(self.parameters)}
        # A parameter given by name, or as a symbol with other assumptions than the expression's
        # (Symbol("w") and Symbol("w", positive=True) are different symbols to sympy).
        self.parameter_by_name = {str(p): i for i, p in enumerate(self.parameters)}
        self.names = [coordinate_name(c) for c in self.q]

    def local_names(self) -> dict[str, Any]:
        """Names for expressions written as strings: coordinates, ``<name>_dot``, parameters, t."""
        names: dict[str, Any] = {str(p): p for p in self.parameters}
        for name, c in zip(self.names, self.q):
            names[name] = c
            names[name + "_dot"] = c.diff(self.t)
        names["t"] = self.t
        return names


def coordinate_name(c: Any) -> str:
    """``q1`` for the dynamicsymbol ``q1(t)``."""
    return c.func.__name__ if isinstance(c, AppliedUndef) else str(c)


class Converter:
    """Appends the operations of sympy expressions to one list, each distinct subexpression once."""

    def __init__(self, symbols: Symbols):
        self.symbols = symbols
        self.ops: list[tuple[str, list[int], float]] = []
        self.memo: dict[Any, int] = {}
        self.where = "the expression"

    def add(self, expr: Any, where: str) -> int:
        """The index of the operation computing ``expr``."""
        self.where = where
        try:
            expr = sympy.sympify(expr, strict=True)
        except sympy.SympifyError:
            raise ConversionError(
                f"{where} is {expr!r}, not an expression; give a sympy expression or a number"
            ) from None
        if not isinstance(expr, sympy.Basic):
            raise ConversionError(
                f"{where} is {expr!r}, not an expression; give a sympy expression or a number"
            )
        if isinstance(expr, sympy.Equality):
            # An equation lhs = rhs stands for the expression lhs − rhs = 0.
            expr = expr.lhs - expr.rhs
        # Post-order without recursion: a deep expression does not reach Python's stack limit.
        stack: list[tuple[Any, bool]] = [(expr, False)]
        while stack:
            node, ready = stack.pop()
            if node in self.memo:
                continue
            children = self._operands(node)
            if ready or not children:
                self.memo[node] = self._emit(node, [self.memo[c] for c in children])
                continue
            stack.append((node, True))
            stack.extend((c, False) for c in children if c not in self.memo)
        return self.memo[expr]

    def _operands(self, node: Any) -> list[Any]:
        if node.is_Number or node.is_NumberSymbol or node.is_Symbol:
            return []
        if isinstance(node, AppliedUndef) or isinstance(node, sympy.Derivative):
            return []
        if isinstance(node, (sympy.Add, sympy.Mul)):
            return list(node.args)
        if isinstance(node, sympy.Pow):
            return [node.base, node.exp]
        if isinstance(node, sympy.atan2):
            return [node.args[0], node.args[1]]
        for f in _RECIPROCALS:
            if isinstance(node, f):
                return [node.args[0]]
        for f in _FUNCTIONS:
            if isinstance(node, f):
                return [node.args[0]]
        return []

    def _push(self, op: str, args: list[int], value: float = 0.0) -> int:
        self.ops.append((op, args, value))
        return len(self.ops) - 1

    def _emit(self, node: Any, args: list[int]) -> int:
        s = self.symbols
        if node.is_Number or node.is_NumberSymbol:
            value = complex(node)
            if value.imag != 0 or not _finite(value.real):
                raise ConversionError(
                    f"{self.where} contains the number {node}, which is not a finite real number"
                )
            return self._push("const", [], value.real)
        if node == s.t:
            return self._push("t", [])
        if node.is_Symbol:
            if node in s.parameter_index:
                return self._push("param", [], float(s.parameter_index[node]))
            if str(node) in s.parameter_by_name:
                return self._push("param", [], float(s.parameter_by_name[str(node)]))
            raise ConversionError(
                f"{self.where} uses the symbol {node}, which has no value: give it in "
                f"parameters={{{node}: ...}} (the parameters are "
                f"{', '.join(map(str, s.parameters)) or 'none'})"
            )
        if isinstance(node, AppliedUndef):
            if node in s.index:
                return self._push("q", [], float(s.index[node]))
            raise ConversionError(
                f"{self.where} uses {node}, which is not among the coordinates q = "
                f"[{', '.join(map(str, s.q))}]; add it to q, or replace it (a generalised speed "
                f"u = q̇ is written as the derivative of its coordinate)"
            )
        if isinstance(node, sympy.Derivative):
            if node in s.velocity:
                return self._push("qd", [], float(s.velocity[node]))
            order = sum(n for _, n in node.variable_count)
            if order > 1 and node.expr in s.index:
                raise ConversionError(
                    f"{self.where} contains the acceleration {node}; a Lagrangian, constraint or "
                    f"force depends on t, q and q̇ only"
                )
            raise ConversionError(
                f"{self.where} contains the derivative {node}, which is not the velocity of a "
                f"coordinate [{', '.join(map(str, s.q))}]"
            )
        if isinstance(node, sympy.Add):
            return self._push("add", args)
        if isinstance(node, sympy.Mul):
            return self._push("mul", args)
        if isinstance(node, sympy.Pow):
            return self._push("pow", args)
        if isinstance(node, sympy.atan2):
            return self._push("atan2", args)
        for f, base in _RECIPROCALS.items():
            if isinstance(node, f):
                inner = self._push(_FUNCTIONS[base], args)
                minus_one = self._push("const", [], -1.0)
                return self._push("pow", [inner, minus_one])
        for f, name in _FUNCTIONS.items():
            if isinstance(node, f):
                return self._push(name, args)
        raise ConversionError(
            f"{self.where} contains {type(node).__name__} ({node}), which chetaev does not "
            f"evaluate; the functions are sqrt (as a power), exp, log, sin, cos, tan, sec, csc, "
            f"cot, their inverses and hyperbolic forms, Abs and atan2"
        )


def _finite(x: float) -> bool:
    return x == x and abs(x) != float("inf")


def _time_symbol(q: Sequence[Any], t: Any | None) -> Any:
    if t is not None:
        return t
    from sympy.physics.mechanics import dynamicsymbols

    return dynamicsymbols._t


def _parameters(parameters: Mapping[Any, float] | None) -> tuple[list[Any], list[float]]:
    symbols, values = [], []
    for k, v in (parameters or {}).items():
        sym = sympy.Symbol(k) if isinstance(k, str) else k
        if not getattr(sym, "is_Symbol", False):
            raise ConversionError(
                f"the parameter {k!r} is not a sympy Symbol or a name; parameters are "
                f"{{symbol: value}}"
            )
        try:
            value = float(v)
        except (TypeError, ValueError):
            raise ConversionError(
                f"the parameter {k} has the value {v!r}; give it a number"
            ) from None
        symbols.append(sym)
        values.append(value)
    return symbols, values


def _loads_to_forces(
    loads: Iterable[Any], frame: Any, symbols: Symbols
) -> list[Any]:
    """Generalised forces of loads ``(point, force)`` and ``(frame, torque)``, mapped through the
    partial velocities ``∂v_P/∂q̇_i`` and ``∂ω_B/∂q̇_i`` in ``frame``:
    ``Q_i = Σ F·∂v_P/∂q̇_i + Σ T·∂ω_B/∂q̇_i``."""
    from sympy.physics.vector import Point, ReferenceFrame

    if frame is None:
        raise ConversionError(
            "loads need the inertial frame: from_sympy(..., loads=[...], frame=N)"
        )
    qd = [c.diff(symbols.t) for c in symbols.q]
    forces = [sympy.S.Zero] * len(qd)
    for load in loads:
        try:
            where, vector = load
        except (TypeError, ValueError):
            raise ConversionError(
                f"a load is (point, force vector) or (frame, torque vector), not {load!r}"
            ) from None
        if isinstance(where, Point):
            velocity = where.vel(frame)
        elif isinstance(where, ReferenceFrame):
            velocity = where.ang_vel_in(frame)
        else:
            raise ConversionError(
                f"a load acts on a Point or a ReferenceFrame, not {where!r}"
            )
        for i, u in enumerate(qd):
            forces[i] += vector.dot(velocity.diff(u, frame))
    return forces


def from_sympy(
    lagrangian: Any = None,
    q: Sequence[Any] = (),
    *,
    constraints: Sequence[Any] = (),
    holonomic: Sequence[Any] = (),
    forces: Sequence[Any] | None = None,
    loads: Iterable[Any] | None = None,
    frame: Any = None,
    bodies: Sequence[Any] | None = None,
    rayleigh: Any = None,
    parameters: Mapping[Any, float] | None = None,
    t: Any = None,
):
    """A chetaev ``Model`` from sympy expressions.

    Parameters
    ----------
    lagrangian
        ``L(t, q, q̇)``: any sympy expression in ``t``, the coordinates ``q_i(t)`` and their
        derivatives, such as ``sympy.physics.mechanics.Lagrangian(N, *bodies)``. May be omitted
        when ``frame`` and ``bodies`` are given (then ``L = Lagrangian(frame, *bodies)``).
    q
        The generalised coordinates, ``dynamicsymbols``; ``q_i.diff(t)`` are the velocities.
    constraints
        Velocity constraints ``f_a(t, q, q̇) = 0``, nonlinear in ``q̇`` allowed. The equations are
        Chetaev's, in Newton form: ``d/dt ∂L/∂q̇ − ∂L/∂q = Σ_a μ_a ∂f_a/∂q̇ + Q``.
    holonomic
        Holonomic constraints ``h_b(t, q) = 0``.
    forces
        Generalised forces ``Q_i(t, q, q̇)`` not derivable from ``L``, one per coordinate.
    loads
        Loads as sympy users write them, ``[(point, force_vector), (frame, torque_vector)]``,
        mapped to ``Q_i = Σ F·∂v_P/∂q̇_i + Σ T·∂ω_B/∂q̇_i`` in ``frame``; added to ``forces``.
    frame
        The inertial frame (for ``loads`` and ``bodies``).
    bodies
        ``RigidBody``/``Particle`` objects whose Lagrangian is used when ``lagrangian`` is None.
    rayleigh
        A Rayleigh dissipation function ``D(t, q, q̇)``: ``Q_i = −∂D/∂q̇_i`` is added.
    parameters
        ``{symbol: value}`` for every symbol other than ``t`` (symbols or their names).
    t
        The time symbol; ``dynamicsymbols._t`` by default.
    """
    from ._chetaev import Model

    q = list(q)
    if not q:
        raise ConversionError("give the coordinates: from_sympy(L, q=[q1, q2, ...])")
    if lagrangian is None:
        if frame is None or not bodies:
            raise ConversionError(
                "give the Lagrangian, or the inertial frame and the bodies: "
                "from_sympy(q=[...], frame=N, bodies=[...])"
            )
        from sympy.physics.mechanics import Lagrangian

        lagrangian = Lagrangian(frame, *bodies)
    t = _time_symbol(q, t)
    for c in q:
        if not isinstance(c, AppliedUndef) or len(c.args) != 1:
            raise ConversionError(
                f"the coordinate {c} is not a function of time alone; make coordinates with "
                f"sympy.physics.mechanics.dynamicsymbols"
            )
        if c.args != (t,):
            other = c.args[0]
            same_name = " (a symbol of the same name with other assumptions)" if str(other) == str(t) else ""
            raise ConversionError(
                f"the coordinate {c} is a function of {other}{same_name}, not of the time symbol "
                f"of dynamicsymbols; make coordinates with sympy.physics.mechanics.dynamicsymbols, "
                f"or give your time symbol as from_sympy(..., t={other})"
            )
    if len(set(q)) != len(q):
        raise ConversionError("a coordinate is listed twice in q")
    params, values = _parameters(parameters)
    symbols = Symbols(t=t, q=q, parameters=params, values=values)
    conv = Converter(symbols)

    root_l = conv.add(lagrangian, "the Lagrangian")
    # Numbered from 1, as the library's messages number them.
    roots_f = [conv.add(f, f"velocity constraint {a}") for a, f in enumerate(constraints, 1)]
    roots_h = [conv.add(h, f"holonomic constraint {b}") for b, h in enumerate(holonomic, 1)]
    q_forces = None
    if forces is not None:
        q_forces = [sympy.sympify(f) for f in forces]
        if len(q_forces) != len(q):
            raise ConversionError(
                f"{len(q_forces)} generalised forces for {len(q)} coordinates; give one per "
                f"coordinate (0 where none acts)"
            )
    if loads:
        mapped = _loads_to_forces(loads, frame, symbols)
        q_forces = mapped if q_forces is None else [a + b for a, b in zip(q_forces, mapped)]
    roots_q = []
    if q_forces is not None:
        roots_q = [
            conv.add(f, f"the generalised force on {name}")
            for name, f in zip(symbols.names, q_forces)
        ]
    root_d = None if rayleigh is None else conv.add(rayleigh, "the Rayleigh function")

    return Model(
        len(q),
        conv.ops,
        root_l,
        constraints=roots_f,
        holonomic=roots_h,
        forces=roots_q,
        dissipation=root_d,
        parameters=[(str(p), v) for p, v in zip(params, values)],
        coordinates=symbols.names,
        symbols=symbols,
        latex=[sympy.latex(sympy.Symbol(name)) for name in symbols.names],
    )


def expression_ops(model: Any, expression: Any) -> tuple[list[tuple[str, list[int], float]], int]:
    """The operations of an expression on ``model``'s coordinates and parameters: a sympy
    expression, or a string in the coordinates' names (``x``, ``x_dot``), the parameters and ``t``."""
    symbols = model.symbols
    if symbols is None:
        raise ConversionError(
            "this model was not made from sympy, so an expression cannot be read against it; "
            "make it with Model.from_sympy"
        )
    if isinstance(expression, str):
        try:
            expression = sympy.parse_expr(expression, local_dict=symbols.local_names())
        except Exception as e:  # sympy raises many kinds for a bad string
            raise ConversionError(f"cannot read the expression {expression!r}: {e}") from None
    conv = Converter(symbols)
    root = conv.add(expression, f"the expression {expression}")
    return conv.ops, root


def _coordinate_index(model: Any, key: Any, speeds_by_name: bool = False) -> int | None:
    """The index of the coordinate ``key`` names: its name (``<name>_dot`` too where
    ``speeds_by_name``), its dynamicsymbol, or that symbol's derivative; None for no coordinate."""
    names = list(model.coordinates)
    symbols = model.symbols
    if isinstance(key, str):
        if speeds_by_name and key.endswith("_dot") and key[:-4] in names:
            key = key[:-4]
        return names.index(key) if key in names else None
    if symbols is not None and key in symbols.index:
        return symbols.index[key]
    if symbols is not None and key in symbols.velocity:
        return symbols.velocity[key]
    return None


def state_vector(model: Any, values: Mapping[Any, float], what: str) -> list[float]:
    """``q0`` or ``q̇0`` given as ``{coordinate: value}`` in the model's order. Keys are the
    coordinates' names, their dynamicsymbols, or (for ``q̇0``) the dynamicsymbols' derivatives."""
    names = list(model.coordinates)
    out: list[float | None] = [None] * len(names)
    for key, value in values.items():
        i = _coordinate_index(model, key)
        if i is None:
            raise ConversionError(
                f"{what} names {key}, which is not a coordinate; the coordinates are "
                f"{', '.join(names)}"
            )
        if out[i] is not None:
            raise ConversionError(f"{what} gives {names[i]} twice")
        try:
            out[i] = float(value)
        except (TypeError, ValueError):
            raise ConversionError(f"{what}: {key} = {value!r} is not a number") from None
    missing = [n for n, v in zip(names, out) if v is None]
    if missing:
        raise ConversionError(f"{what} gives no value for {', '.join(missing)}")
    return [float(v) for v in out]  # type: ignore[arg-type]


def indices(model: Any, items: Iterable[Any] | None, what: str) -> list[int] | None:
    """Coordinate indices (from 0) of ``items``: ints, the coordinates' names, their
    dynamicsymbols, or (for speeds) the dynamicsymbols' derivatives. None stays None."""
    if items is None:
        return None
    names = list(model.coordinates)
    out = []
    for item in items:
        if isinstance(item, bool):
            raise ConversionError(f"{what}: {item!r} is not a coordinate")
        if isinstance(item, int):
            if not 0 <= item < len(names):
                raise ConversionError(
                    f"{what}: index {item} is out of range for {len(names)} coordinates "
                    f"(indices count from 0)"
                )
            i = item
        else:
            i = _coordinate_index(model, item, speeds_by_name=True)
        if i is None:
            raise ConversionError(
                f"{what}: {item} is not a coordinate; the coordinates are {', '.join(names)}"
            )
        out.append(i)
    return out
