//! The recording scalar: a node of the thread's [`Graph`](super::Graph) and its value at the
//! recorded point, with the arithmetic and elementary functions of [`Real`](crate::model::Real).

use std::cmp::Ordering;
use std::fmt;
use std::iter::{Product, Sum};
use std::ops::{
    Add, AddAssign, Div, DivAssign, Mul, MulAssign, Neg, Rem, RemAssign, Sub, SubAssign,
};

use num_dual::{DualNum, DualStruct, Mappable};
use num_traits::{FromPrimitive, Inv, Num, One, Signed, Zero};

use super::{with_graph, Deps, Fun, Graph, Node, FREE};

/// A recorded value: a node of the expression graph being recorded on this thread (or a free
/// constant), with its value at the recorded point. Only the library makes them, while recording a
/// model ([`record`](super::record)); a model sees it as any other [`Real`](crate::model::Real).
#[derive(Clone, Copy, Debug)]
pub struct Sym {
    id: u32,
    v: f64,
}

impl Sym {
    /// A free constant (no node).
    #[inline]
    pub const fn constant(v: f64) -> Self {
        Self { id: FREE, v }
    }

    /// A new input of class `class` with value `v` (while recording).
    pub fn input(class: Deps, v: f64) -> Self {
        let id = with_graph(|g| g.input(class, v));
        Self { id, v }
    }

    /// The node of this value in the recording graph (a constant node for a free constant).
    pub fn node(self) -> u32 {
        if self.id == FREE {
            with_graph(|g| g.constant_node(self.v))
        } else {
            self.id
        }
    }

    /// The node id, without making one for a free constant (`FREE` then).
    pub(crate) fn node_id(self) -> u32 {
        self.id
    }

    /// The value at the recorded point.
    pub fn value(self) -> f64 {
        self.v
    }

    fn lift(self, g: &mut Graph) -> u32 {
        if self.id == FREE {
            g.constant_node(self.v)
        } else {
            self.id
        }
    }

    fn from_node(g: &Graph, id: u32) -> Self {
        match g.constant(id) {
            Some(c) => Self::constant(c),
            None => Self {
                id,
                v: g.values[id as usize],
            },
        }
    }

    #[inline]
    fn binary(self, other: Self, make: fn(u32, u32) -> Node) -> Self {
        if self.id == FREE && other.id == FREE {
            let n = make(0, 1);
            let v = [self.v, other.v];
            return Self::constant(n.eval(|o| v[o as usize]));
        }
        with_graph(|g| {
            let (a, b) = (self.lift(g), other.lift(g));
            let id = g.push(make(a, b));
            Self::from_node(g, id)
        })
    }

    #[inline]
    fn unary(self, make: impl Fn(u32) -> Node) -> Self {
        if self.id == FREE {
            let n = make(0);
            return Self::constant(n.eval(|_| self.v));
        }
        with_graph(|g| {
            let id = g.push(make(self.id));
            Self::from_node(g, id)
        })
    }

    fn fun(self, f: Fun) -> Self {
        // The bounds of the domains that the derivatives do not carry (module docs).
        let bounds: &[f64] = match f {
            Fun::Ln | Fun::Log2 | Fun::Log10 => &[0.0],
            Fun::Ln1p => &[-1.0],
            Fun::Atanh => &[-1.0, 1.0],
            _ => &[],
        };
        for &bound in bounds {
            self.guard(Sym::constant(bound), true);
        }
        self.unary(|a| Node::Fun(f, a))
    }

    /// Compares two values and, when either is recorded, keeps the comparison as a guard.
    fn compare(self, other: Self) -> Option<Ordering> {
        self.guard(other, false)
    }

    /// `self.partial_cmp(other)`, kept as a guard (a bound of a domain or a branch) when either
    /// is recorded.
    fn guard(self, other: Self, domain: bool) -> Option<Ordering> {
        let outcome = self.v.partial_cmp(&other.v);
        if self.id != FREE || other.id != FREE {
            with_graph(|g| {
                let (a, b) = (self.lift(g), other.lift(g));
                g.guard(a, b, outcome, domain);
            });
        }
        outcome
    }

    /// A value that the graph cannot follow: the recording is marked as escaped.
    fn escape(self) -> Self {
        if self.id != FREE {
            with_graph(|g| g.escaped = true);
        }
        Self::constant(self.v)
    }
}

impl fmt::Display for Sym {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(&self.v, f)
    }
}

impl PartialEq for Sym {
    fn eq(&self, other: &Self) -> bool {
        self.compare(*other) == Some(Ordering::Equal)
    }
}
impl PartialOrd for Sym {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        self.compare(*other)
    }
}
impl PartialEq<f64> for Sym {
    fn eq(&self, other: &f64) -> bool {
        self.compare(Sym::constant(*other)) == Some(Ordering::Equal)
    }
}
impl PartialOrd<f64> for Sym {
    fn partial_cmp(&self, other: &f64) -> Option<Ordering> {
        self.compare(Sym::constant(*other))
    }
}

macro_rules! binary_ops {
    ($($trt:ident $mth:ident $node:ident $atrt:ident $amth:ident;)*) => {$(
        impl $trt for Sym {
            type Output = Sym;
            #[inline]
            fn $mth(self, rhs: Sym) -> Sym {
                self.binary(rhs, Node::$node)
            }
        }
        impl $trt<&Sym> for Sym {
            type Output = Sym;
            #[inline]
            fn $mth(self, rhs: &Sym) -> Sym {
                self.binary(*rhs, Node::$node)
            }
        }
        impl $trt<Sym> for &Sym {
            type Output = Sym;
            #[inline]
            fn $mth(self, rhs: Sym) -> Sym {
                (*self).binary(rhs, Node::$node)
            }
        }
        impl $trt<&Sym> for &Sym {
            type Output = Sym;
            #[inline]
            fn $mth(self, rhs: &Sym) -> Sym {
                (*self).binary(*rhs, Node::$node)
            }
        }
        impl $trt<f64> for Sym {
            type Output = Sym;
            #[inline]
            fn $mth(self, rhs: f64) -> Sym {
                self.binary(Sym::constant(rhs), Node::$node)
            }
        }
        impl $atrt for Sym {
            #[inline]
            fn $amth(&mut self, rhs: Sym) {
                *self = self.binary(rhs, Node::$node);
            }
        }
        impl $atrt<f64> for Sym {
            #[inline]
            fn $amth(&mut self, rhs: f64) {
                *self = self.binary(Sym::constant(rhs), Node::$node);
            }
        }
    )*};
}

binary_ops! {
    Add add Add AddAssign add_assign;
    Sub sub Sub SubAssign sub_assign;
    Mul mul Mul MulAssign mul_assign;
    Div div Div DivAssign div_assign;
}

// The remainder is not differentiable in the way the graph needs: a recording that uses it is not
// used (the dual-number path remains).
impl Rem for Sym {
    type Output = Sym;
    fn rem(self, rhs: Sym) -> Sym {
        let v = self.v % rhs.v;
        self.escape();
        rhs.escape();
        Sym::constant(v)
    }
}
impl Rem<&Sym> for Sym {
    type Output = Sym;
    fn rem(self, rhs: &Sym) -> Sym {
        self % *rhs
    }
}
impl Rem<Sym> for &Sym {
    type Output = Sym;
    fn rem(self, rhs: Sym) -> Sym {
        *self % rhs
    }
}
impl Rem<&Sym> for &Sym {
    type Output = Sym;
    fn rem(self, rhs: &Sym) -> Sym {
        *self % *rhs
    }
}
impl Rem<f64> for Sym {
    type Output = Sym;
    fn rem(self, rhs: f64) -> Sym {
        self % Sym::constant(rhs)
    }
}
impl RemAssign for Sym {
    fn rem_assign(&mut self, rhs: Sym) {
        *self = *self % rhs;
    }
}
impl RemAssign<f64> for Sym {
    fn rem_assign(&mut self, rhs: f64) {
        *self = *self % rhs;
    }
}

impl Neg for Sym {
    type Output = Sym;
    #[inline]
    fn neg(self) -> Sym {
        self.unary(Node::Neg)
    }
}
impl Neg for &Sym {
    type Output = Sym;
    #[inline]
    fn neg(self) -> Sym {
        (*self).unary(Node::Neg)
    }
}

impl Zero for Sym {
    fn zero() -> Self {
        Sym::constant(0.0)
    }
    fn is_zero(&self) -> bool {
        *self == 0.0
    }
}
impl One for Sym {
    fn one() -> Self {
        Sym::constant(1.0)
    }
}
impl Num for Sym {
    type FromStrRadixErr = <f64 as Num>::FromStrRadixErr;
    fn from_str_radix(s: &str, radix: u32) -> Result<Self, Self::FromStrRadixErr> {
        f64::from_str_radix(s, radix).map(Sym::constant)
    }
}
impl Signed for Sym {
    fn abs(&self) -> Self {
        self.fun(Fun::Abs)
    }
    fn abs_sub(&self, other: &Self) -> Self {
        let d = *self - *other;
        if d > 0.0 {
            d
        } else {
            Sym::constant(0.0)
        }
    }
    fn signum(&self) -> Self {
        self.fun(Fun::Signum)
    }
    fn is_positive(&self) -> bool {
        *self > 0.0
    }
    fn is_negative(&self) -> bool {
        *self < 0.0
    }
}
impl Inv for Sym {
    type Output = Sym;
    fn inv(self) -> Sym {
        self.fun(Fun::Recip)
    }
}
impl Sum for Sym {
    fn sum<I: Iterator<Item = Sym>>(iter: I) -> Sym {
        iter.fold(Sym::zero(), |a, b| a + b)
    }
}
impl<'a> Sum<&'a Sym> for Sym {
    fn sum<I: Iterator<Item = &'a Sym>>(iter: I) -> Sym {
        iter.fold(Sym::zero(), |a, b| a + *b)
    }
}
impl Product for Sym {
    fn product<I: Iterator<Item = Sym>>(iter: I) -> Sym {
        iter.fold(Sym::one(), |a, b| a * b)
    }
}
impl<'a> Product<&'a Sym> for Sym {
    fn product<I: Iterator<Item = &'a Sym>>(iter: I) -> Sym {
        iter.fold(Sym::one(), |a, b| a * *b)
    }
}
impl FromPrimitive for Sym {
    fn from_i64(n: i64) -> Option<Self> {
        Some(Sym::constant(n as f64))
    }
    fn from_u64(n: u64) -> Option<Self> {
        Some(Sym::constant(n as f64))
    }
    fn from_f64(n: f64) -> Option<Self> {
        Some(Sym::constant(n))
    }
}
impl From<f64> for Sym {
    fn from(v: f64) -> Self {
        Sym::constant(v)
    }
}
impl DualStruct<Sym, f64> for Sym {
    type Real = f64;
    type Inner = f64;
    /// The value; taking it out of a recorded value marks the recording as escaped (the graph
    /// cannot follow what the model does with it).
    fn re(&self) -> f64 {
        self.escape().v
    }
    fn from_inner(inner: &f64) -> Self {
        Sym::constant(*inner)
    }
}
impl Mappable<Sym> for Sym {
    type Output<O> = O;
    fn map_dual<M: FnOnce(Sym) -> O, O>(self, f: M) -> O {
        f(self)
    }
}

/// The methods that record one elementary function of the value: `$mth` as `Fun::$fun`.
macro_rules! elementary_functions {
    ($($mth:ident $fun:ident;)*) => {$(
        fn $mth(&self) -> Self {
            self.fun(Fun::$fun)
        }
    )*};
}

impl DualNum<f64> for Sym {
    const NDERIV: usize = 0;

    elementary_functions! {
        recip Recip;
        sqrt Sqrt;
        cbrt Cbrt;
        exp Exp;
        exp2 Exp2;
        exp_m1 ExpM1;
        ln Ln;
        log2 Log2;
        log10 Log10;
        ln_1p Ln1p;
        sin Sin;
        cos Cos;
        tan Tan;
        asin Asin;
        acos Acos;
        atan Atan;
        sinh Sinh;
        cosh Cosh;
        tanh Tanh;
        asinh Asinh;
        acosh Acosh;
        atanh Atanh;
    }
    fn powi(&self, n: i32) -> Self {
        self.unary(|a| Node::Powi(a, n))
    }
    fn powf(&self, n: f64) -> Self {
        self.unary(|a| Node::Powf(a, n))
    }
    fn log(&self, base: f64) -> Self {
        self.fun(Fun::Ln) / base.ln()
    }
    fn sin_cos(&self) -> (Self, Self) {
        (self.sin(), self.cos())
    }
    fn atan2(&self, other: Self) -> Self {
        self.binary(other, Node::Atan2)
    }
    // The spherical Bessel functions are rare in mechanics: their series branch near zero is not
    // recorded, so a recording that uses them is not used.
    fn sph_j0(&self) -> Self {
        Sym::constant(self.escape().v.sph_j0())
    }
    fn sph_j1(&self) -> Self {
        Sym::constant(self.escape().v.sph_j1())
    }
    fn sph_j2(&self) -> Self {
        Sym::constant(self.escape().v.sph_j2())
    }
}
