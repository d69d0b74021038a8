//! Straight-line programs over `f64`, compiled to machine code by Cranelift, behind a safe
//! interface.
//!
//! A [`Program`] is a list of operations in dependency order, each on earlier ones: inputs (from
//! two arrays, so that a caller can pass two slices it already has without copying them into one),
//! constants, the four arithmetic operations, negation, square root and absolute value, and calls
//! of plain functions (`extern "C" fn(f64) -> f64` and the like) for everything else (`sin`,
//! `exp`, `powi`, ...). Some operations are outputs, written to two arrays; some pairs are *guards*, comparisons whose
//! outcome was known when the program was made. [`Native::compile`] turns a program into one
//! function of the host machine; [`Native::call`] runs it on two input slices, writes the two
//! output slices and says whether every guard still holds.
//!
//! The generated code performs the same IEEE operations as [`Program::eval`], in the same order
//! and without fusing or reassociating any, and calls the same functions: its outputs equal the
//! interpreter's bit for bit.
//!
//! This crate is the only one of the workspace with `unsafe` code: the call into the generated
//! function and the release of its memory. Their soundness rests on [`Native::compile`] refusing
//! any program that reads an input or an operation that is not there
//! ([`ProgramError`]), and on [`Native::call`] checking the lengths of its slices.
//!
//! ```
//! use chetaev_native::{Native, Op, Program};
//!
//! extern "C" fn sin(x: f64) -> f64 {
//!     x.sin()
//! }
//! // y = sin(x0) · x1 + 2, with x0 in the first array and x1 in the second
//! let p = Program {
//!     inputs: [1, 1],
//!     ops: vec![
//!         Op::Input(0, 0),
//!         Op::Input(1, 0),
//!         Op::Unary(sin, 0),
//!         Op::Mul(2, 1),
//!         Op::Const(2.0),
//!         Op::Add(3, 4),
//!     ],
//!     outputs: [vec![5], vec![]],
//!     guards: vec![],
//! };
//! let native = Native::compile(&p).expect("a supported host");
//! let mut y = [0.0];
//! assert!(native.call([&[0.5], &[3.0]], [&mut y, &mut []]).expect("lengths fit"));
//! assert_eq!(y[0], 0.5f64.sin() * 3.0 + 2.0);
//! ```

use std::cmp::Ordering;

#[cfg(feature = "jit")]
use cranelift_codegen::ir::condcodes::FloatCC;
#[cfg(feature = "jit")]
use cranelift_codegen::ir::{types, AbiParam, InstBuilder, MemFlagsData, Value};
#[cfg(feature = "jit")]
use cranelift_codegen::settings::{self, Configurable};
#[cfg(feature = "jit")]
use cranelift_frontend::{FunctionBuilder, FunctionBuilderContext};
#[cfg(feature = "jit")]
use cranelift_jit::{JITBuilder, JITModule};
#[cfg(feature = "jit")]
use cranelift_module::{default_libcall_names, Linkage, Module};

/// How hard the code generator works on a program. Both efforts perform the program's operations
/// as written (nothing fused or reassociated), so their outputs are equal bit for bit; they differ
/// in the time taken to compile and in how the values are kept in registers.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Effort {
    /// No optimisation and a single-pass register allocator: for the rolling disc's right-hand
    /// side (361 operations), a quarter of [`Effort::Full`]'s compile time, for code about 1.3
    /// times as slow (`examples/first_solve` of `chetaev-bench`).
    Quick,
    /// Cranelift's optimisations and its backtracking register allocator.
    #[default]
    Full,
}

impl Effort {
    #[cfg(feature = "jit")]
    fn opt_level(self) -> &'static str {
        match self {
            Self::Quick => "none",
            Self::Full => "speed",
        }
    }

    #[cfg(feature = "jit")]
    fn register_allocator(self) -> &'static str {
        match self {
            Self::Quick => "single_pass",
            Self::Full => "backtracking",
        }
    }
}

/// A function of one argument the generated code may call.
pub type Unary = extern "C" fn(f64) -> f64;
/// A function of two arguments the generated code may call.
pub type Binary = extern "C" fn(f64, f64) -> f64;
/// A function of a number and an integer (`powi`) the generated code may call.
pub type WithInt = extern "C" fn(f64, i32) -> f64;

/// One operation of a [`Program`]; operands are indices of earlier operations.
#[derive(Clone, Copy, Debug)]
pub enum Op {
    /// Entry `i` of input array `a` (0 or 1).
    Input(u8, u32),
    /// A constant.
    Const(f64),
    /// `a + b`.
    Add(u32, u32),
    /// `a − b`.
    Sub(u32, u32),
    /// `a · b`.
    Mul(u32, u32),
    /// `a / b`.
    Div(u32, u32),
    /// `−a`.
    Neg(u32),
    /// `√a` (correctly rounded, as `f64::sqrt`).
    Sqrt(u32),
    /// `|a|`.
    Abs(u32),
    /// `f(a)`.
    Unary(Unary, u32),
    /// `f(a, b)`.
    Binary(Binary, u32, u32),
    /// `f(a, i)`.
    WithInt(WithInt, u32, i32),
}

impl Op {
    /// The operations this one reads: the first `count` of the pair returned as `(pair, count)`.
    pub fn operands(&self) -> ([u32; 2], usize) {
        match *self {
            Op::Input(..) | Op::Const(_) => ([0, 0], 0),
            Op::Neg(a) | Op::Sqrt(a) | Op::Abs(a) | Op::Unary(_, a) | Op::WithInt(_, a, _) => {
                ([a, 0], 1)
            }
            Op::Add(a, b) | Op::Sub(a, b) | Op::Mul(a, b) | Op::Div(a, b) | Op::Binary(_, a, b) => {
                ([a, b], 2)
            }
        }
    }
}

/// A comparison whose outcome was known when the program was made: it holds where
/// `a.partial_cmp(&b) == outcome`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Guard {
    /// The left operation.
    pub a: u32,
    /// The right operation.
    pub b: u32,
    /// The outcome that holds (`None`: unordered, a NaN on either side).
    pub outcome: Option<Ordering>,
}

/// A straight-line program; see the crate docs.
#[derive(Clone, Debug, Default)]
pub struct Program {
    /// The lengths of the two input arrays.
    pub inputs: [usize; 2],
    /// The operations, each on earlier ones.
    pub ops: Vec<Op>,
    /// The operations written out to each of the two output arrays, in order.
    pub outputs: [Vec<u32>; 2],
    /// The guards.
    pub guards: Vec<Guard>,
}

/// Why a program was refused, or could not be compiled.
#[derive(Debug, thiserror::Error, PartialEq)]
#[non_exhaustive]
pub enum ProgramError {
    /// An operation reads an operation at or after itself, or one that does not exist.
    #[error("operation {op} reads operation {operand}, which does not come before it")]
    Operand {
        /// The operation.
        op: usize,
        /// What it reads.
        operand: u32,
    },
    /// An input array or index is out of range.
    #[error("operation {op} reads entry {input} of input array {array}, of length {len}")]
    Input {
        /// The operation.
        op: usize,
        /// The array read (0 or 1).
        array: u8,
        /// The entry read.
        input: u32,
        /// The array's length (0 for an array beyond the two).
        len: usize,
    },
    /// An output or a guard names an operation that does not exist.
    #[error("an output or guard names operation {0}, beyond the program's end")]
    Reference(u32),
    /// Slices of the wrong length given to [`Program::eval`].
    #[error(transparent)]
    Lengths(#[from] LengthError),
    /// The code generator failed, or this host is not one Cranelift generates code for.
    #[error("no machine code for this program on this host: {0}")]
    Backend(String),
}

/// Slices of the wrong length given to [`Native::call`] or [`Program::eval`].
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
#[error("the program takes input arrays of {inputs:?} entries and writes output arrays of {outputs:?}; got slices of {got_inputs:?} and {got_outputs:?}")]
pub struct LengthError {
    /// The lengths of the program's input arrays.
    pub inputs: [usize; 2],
    /// The lengths of its output arrays.
    pub outputs: [usize; 2],
    /// The lengths of the input slices given.
    pub got_inputs: [usize; 2],
    /// The lengths of the output slices given.
    pub got_outputs: [usize; 2],
}

/// The lengths of the slices given against the program's, as an error where they differ.
fn lengths(
    inputs: [usize; 2],
    outputs: [usize; 2],
    got_inputs: [usize; 2],
    got_outputs: [usize; 2],
) -> Result<(), LengthError> {
    if inputs == got_inputs && outputs == got_outputs {
        Ok(())
    } else {
        Err(LengthError {
            inputs,
            outputs,
            got_inputs,
            got_outputs,
        })
    }
}

impl Program {
    /// Checks that every operand, input, output and guard refers to something that exists.
    pub fn check(&self) -> Result<(), ProgramError> {
        for (i, op) in self.ops.iter().enumerate() {
            if let Op::Input(array, input) = *op {
                let len = self.inputs.get(usize::from(array)).copied().unwrap_or(0);
                if input as usize >= len {
                    return Err(ProgramError::Input {
                        op: i,
                        array,
                        input,
                        len,
                    });
                }
            }
            let (operands, count) = op.operands();
            if let Some(&operand) = operands[..count].iter().find(|&&o| o as usize >= i) {
                return Err(ProgramError::Operand { op: i, operand });
            }
        }
        let len = self.ops.len();
        let names = self.outputs[0]
            .iter()
            .chain(&self.outputs[1])
            .chain(self.guards.iter().flat_map(|g| [&g.a, &g.b]));
        match names.copied().find(|&o| o as usize >= len) {
            Some(o) => Err(ProgramError::Reference(o)),
            None => Ok(()),
        }
    }

    fn output_lengths(&self) -> [usize; 2] {
        [self.outputs[0].len(), self.outputs[1].len()]
    }

    /// Evaluates the program by interpretation (the reference the compiled code equals): writes
    /// the outputs, and returns whether every guard holds. A program that fails
    /// [`Program::check`], or slices of other lengths than the program's, give a
    /// [`ProgramError`] and write nothing.
    pub fn eval(
        &self,
        inputs: [&[f64]; 2],
        outputs: [&mut [f64]; 2],
    ) -> Result<bool, ProgramError> {
        self.check()?;
        lengths(
            self.inputs,
            self.output_lengths(),
            inputs.map(<[f64]>::len),
            [outputs[0].len(), outputs[1].len()],
        )?;
        let mut v: Vec<f64> = Vec::with_capacity(self.ops.len());
        for op in &self.ops {
            let x = |i: u32| v[i as usize];
            let value = match *op {
                Op::Input(a, i) => inputs[usize::from(a)][i as usize],
                Op::Const(c) => c,
                Op::Add(a, b) => x(a) + x(b),
                Op::Sub(a, b) => x(a) - x(b),
                Op::Mul(a, b) => x(a) * x(b),
                Op::Div(a, b) => x(a) / x(b),
                Op::Neg(a) => -x(a),
                Op::Sqrt(a) => x(a).sqrt(),
                Op::Abs(a) => x(a).abs(),
                Op::Unary(f, a) => f(x(a)),
                Op::Binary(f, a, b) => f(x(a), x(b)),
                Op::WithInt(f, a, n) => f(x(a), n),
            };
            v.push(value);
        }
        for (out, ids) in outputs.into_iter().zip(&self.outputs) {
            for (dst, &o) in out.iter_mut().zip(ids) {
                *dst = v[o as usize];
            }
        }
        Ok(self
            .guards
            .iter()
            .all(|g| v[g.a as usize].partial_cmp(&v[g.b as usize]) == g.outcome))
    }
}

/// The signature of every generated function: the two input arrays, the two output arrays;
/// returns 1 where every guard holds and 0 otherwise.
#[cfg(feature = "jit")]
type Entry = extern "C" fn(*const f64, *const f64, *mut f64, *mut f64) -> u32;

/// A [`Program`] compiled to machine code; see the crate docs.
pub struct Native {
    /// Owns the code's memory, released on drop.
    #[cfg(feature = "jit")]
    module: Option<JITModule>,
    #[cfg(feature = "jit")]
    entry: Entry,
    /// Without a code generator no program compiles, so no value of this type exists.
    #[cfg(not(feature = "jit"))]
    never: std::convert::Infallible,
    inputs: [usize; 2],
    outputs: [usize; 2],
    operations: usize,
}

// SAFETY: after `finalize_definitions` the module's code and data are never written again; `Native`
// only reads the entry point, and calling the generated function touches nothing but the slices
// passed to it (and the pure functions the program names, which are `extern "C" fn`s safe to call
// from any thread). The module itself is only touched again by `drop`, which needs `&mut self`.
#[cfg(feature = "jit")]
#[allow(unsafe_code)]
unsafe impl Send for Native {}
// SAFETY: as for `Send`: a shared `&Native` gives access only to the immutable entry point.
#[cfg(feature = "jit")]
#[allow(unsafe_code)]
unsafe impl Sync for Native {}

impl std::fmt::Debug for Native {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Native")
            .field("inputs", &self.inputs)
            .field("outputs", &self.outputs)
            .field("operations", &self.operations)
            .finish_non_exhaustive()
    }
}

#[cfg(feature = "jit")]
impl Drop for Native {
    fn drop(&mut self) {
        if let Some(module) = self.module.take() {
            // SAFETY: the only pointer into the module's memory is `self.entry`, which dies with
            // `self`; no call can be running, since that would borrow `self`.
            #[allow(unsafe_code)]
            unsafe {
                module.free_memory();
            }
        }
    }
}

#[cfg(feature = "jit")]
fn backend(e: impl std::fmt::Display) -> ProgramError {
    ProgramError::Backend(e.to_string())
}

impl Native {
    /// Whether this build has the code generator (the feature `jit`): without it every
    /// [`Native::compile`] is refused.
    pub const fn available() -> bool {
        cfg!(feature = "jit")
    }

    /// Compiles `program` for this machine with [`Effort::Full`]: refused where
    /// [`Program::check`] fails, or where Cranelift has no code generator for the host.
    pub fn compile(program: &Program) -> Result<Self, ProgramError> {
        Self::compile_with(program, Effort::Full)
    }

    /// Compiles `program` for this machine, working as hard as `effort` says: refused where
    /// [`Program::check`] fails, or where Cranelift has no code generator for the host. Every
    /// effort gives a function whose outputs are equal bit for bit.
    #[cfg(feature = "jit")]
    pub fn compile_with(program: &Program, effort: Effort) -> Result<Self, ProgramError> {
        program.check()?;
        let mut flags = settings::builder();
        for (name, value) in [
            ("use_colocated_libcalls", "false"),
            ("is_pic", "false"),
            ("opt_level", effort.opt_level()),
            ("regalloc_algorithm", effort.register_allocator()),
            // The verifier checks the generated IR, which is well formed by construction once
            // `Program::check` has passed: it runs in debug builds, where the tests are.
            (
                "enable_verifier",
                if cfg!(debug_assertions) {
                    "true"
                } else {
                    "false"
                },
            ),
        ] {
            flags.set(name, value).map_err(backend)?;
        }
        let isa = cranelift_native::builder()
            .map_err(backend)?
            .finish(settings::Flags::new(flags))
            .map_err(backend)?;
        let mut module = JITModule::new(JITBuilder::with_isa(isa, default_libcall_names()));
        let config = module.target_config();
        let ptr = config.pointer_type();
        let mut ctx = module.make_context();
        for _ in 0..4 {
            ctx.func.signature.params.push(AbiParam::new(ptr));
        }
        ctx.func.signature.returns.push(AbiParam::new(types::I32));
        let unary = {
            let mut s = module.make_signature();
            s.params.push(AbiParam::new(types::F64));
            s.returns.push(AbiParam::new(types::F64));
            s
        };
        let binary = {
            let mut s = unary.clone();
            s.params.push(AbiParam::new(types::F64));
            s
        };
        let with_int = {
            let mut s = unary.clone();
            s.params.push(AbiParam::new(types::I32));
            s
        };
        let mut fctx = FunctionBuilderContext::new();
        {
            let mut b = FunctionBuilder::new(&mut ctx.func, &mut fctx);
            let (unary, binary, with_int) = (
                b.import_signature(unary),
                b.import_signature(binary),
                b.import_signature(with_int),
            );
            let block = b.create_block();
            b.append_block_params_for_function_params(block);
            b.switch_to_block(block);
            b.seal_block(block);
            let params = b.block_params(block);
            let (input, output) = ([params[0], params[1]], [params[2], params[3]]);
            let mem = MemFlagsData::trusted();
            let mut v: Vec<Value> = Vec::with_capacity(program.ops.len());
            for op in &program.ops {
                let x = |i: u32| v[i as usize];
                let value = match *op {
                    Op::Input(a, i) => {
                        b.ins()
                            .load(types::F64, mem, input[usize::from(a)], 8 * i as i32)
                    }
                    Op::Const(c) => b.ins().f64const(c),
                    Op::Add(a, c) => b.ins().fadd(x(a), x(c)),
                    Op::Sub(a, c) => b.ins().fsub(x(a), x(c)),
                    Op::Mul(a, c) => b.ins().fmul(x(a), x(c)),
                    Op::Div(a, c) => b.ins().fdiv(x(a), x(c)),
                    Op::Neg(a) => b.ins().fneg(x(a)),
                    Op::Sqrt(a) => b.ins().sqrt(x(a)),
                    Op::Abs(a) => b.ins().fabs(x(a)),
                    Op::Unary(f, a) => {
                        let callee = b.ins().iconst(ptr, f as usize as i64);
                        let call = b.ins().call_indirect(unary, callee, &[x(a)]);
                        b.inst_results(call)[0]
                    }
                    Op::Binary(f, a, c) => {
                        let callee = b.ins().iconst(ptr, f as usize as i64);
                        let call = b.ins().call_indirect(binary, callee, &[x(a), x(c)]);
                        b.inst_results(call)[0]
                    }
                    Op::WithInt(f, a, n) => {
                        let callee = b.ins().iconst(ptr, f as usize as i64);
                        let n = b.ins().iconst(types::I32, i64::from(n));
                        let call = b.ins().call_indirect(with_int, callee, &[x(a), n]);
                        b.inst_results(call)[0]
                    }
                };
                v.push(value);
            }
            for (&out, ids) in output.iter().zip(&program.outputs) {
                for (j, &o) in ids.iter().enumerate() {
                    b.ins().store(mem, v[o as usize], out, 8 * j as i32);
                }
            }
            let mut held = b.ins().iconst(types::I8, 1);
            for g in &program.guards {
                let (x, y) = (v[g.a as usize], v[g.b as usize]);
                let cc = match g.outcome {
                    Some(Ordering::Less) => FloatCC::LessThan,
                    Some(Ordering::Equal) => FloatCC::Equal,
                    Some(Ordering::Greater) => FloatCC::GreaterThan,
                    None => FloatCC::Unordered,
                };
                let holds = b.ins().fcmp(cc, x, y);
                held = b.ins().band(held, holds);
            }
            let held = b.ins().uextend(types::I32, held);
            b.ins().return_(&[held]);
            b.finalize(config);
        }
        let id = module
            .declare_function("program", Linkage::Export, &ctx.func.signature)
            .map_err(backend)?;
        module.define_function(id, &mut ctx).map_err(backend)?;
        module.clear_context(&mut ctx);
        module.finalize_definitions().map_err(backend)?;
        let code = module.get_finalized_function(id);
        // SAFETY: `code` is the finalised function just defined with the signature `Entry`
        // (four pointers in, a 32-bit integer out, the host's default calling convention, which
        // is `extern "C"`'s).
        #[allow(unsafe_code)]
        let entry = unsafe { std::mem::transmute::<*const u8, Entry>(code) };
        Ok(Self {
            module: Some(module),
            entry,
            inputs: program.inputs,
            outputs: program.output_lengths(),
            operations: program.ops.len(),
        })
    }

    /// Without the `jit` feature there is no code generator: every program is refused with
    /// [`ProgramError::Backend`] once [`Program::check`] has passed, and callers keep to
    /// [`Program::eval`] or their own interpreter.
    #[cfg(not(feature = "jit"))]
    pub fn compile_with(program: &Program, effort: Effort) -> Result<Self, ProgramError> {
        let _ = effort;
        program.check()?;
        Err(ProgramError::Backend(
            "this build has no code generator: the `jit` feature of chetaev-native (the `native` \
             feature of chetaev, on by default) is off"
                .to_owned(),
        ))
    }

    /// Runs the compiled program on the two input arrays: writes the two output arrays and
    /// returns whether every guard holds. Slices of other lengths than the program's give a
    /// [`LengthError`].
    #[cfg(not(feature = "jit"))]
    pub fn call(&self, _: [&[f64]; 2], _: [&mut [f64]; 2]) -> Result<bool, LengthError> {
        match self.never {}
    }

    /// Runs the compiled program on the two input arrays: writes the two output arrays and
    /// returns whether every guard holds. Slices of other lengths than the program's give a
    /// [`LengthError`].
    #[cfg(feature = "jit")]
    #[inline]
    pub fn call(&self, inputs: [&[f64]; 2], outputs: [&mut [f64]; 2]) -> Result<bool, LengthError> {
        let [out0, out1] = outputs;
        lengths(
            self.inputs,
            self.outputs,
            [inputs[0].len(), inputs[1].len()],
            [out0.len(), out1.len()],
        )?;
        // The generated function reads `inputs[a][i]` only for the `Op::Input(a, i)` of the
        // program, each within the program's lengths (checked by `compile`), and writes
        // `outputs[a][j]` for `j` below the program's output lengths; the lengths were just
        // checked. It keeps no pointer after returning.
        let held = (self.entry)(
            inputs[0].as_ptr(),
            inputs[1].as_ptr(),
            out0.as_mut_ptr(),
            out1.as_mut_ptr(),
        );
        Ok(held != 0)
    }

    /// The lengths of the two input arrays.
    pub fn inputs(&self) -> [usize; 2] {
        self.inputs
    }

    /// The lengths of the two output arrays.
    pub fn outputs(&self) -> [usize; 2] {
        self.outputs
    }

    /// The number of operations compiled.
    pub fn operations(&self) -> usize {
        self.operations
    }
}

#[cfg(all(test, feature = "jit"))]
mod tests {
    use super::*;

    extern "C" fn sin(x: f64) -> f64 {
        x.sin()
    }
    extern "C" fn atan2(y: f64, x: f64) -> f64 {
        y.atan2(x)
    }
    extern "C" fn powi(x: f64, n: i32) -> f64 {
        x.powi(n)
    }

    /// Every kind of operation, two outputs and a guard `x0 < x1`.
    fn every_op() -> Program {
        Program {
            inputs: [1, 1],
            ops: vec![
                Op::Input(0, 0),
                Op::Input(1, 0),
                Op::Const(0.25),
                Op::Add(0, 1),
                Op::Sub(3, 2),
                Op::Mul(4, 0),
                Op::Div(5, 1),
                Op::Neg(6),
                Op::Abs(7),
                Op::Sqrt(8),
                Op::Unary(sin, 9),
                Op::Binary(atan2, 10, 1),
                Op::WithInt(powi, 11, -3),
            ],
            outputs: [vec![12], vec![7]],
            guards: vec![Guard {
                a: 0,
                b: 1,
                outcome: Some(Ordering::Less),
            }],
        }
    }

    #[test]
    fn compiled_code_equals_the_interpreter_bit_for_bit_and_checks_its_guards() {
        let p = every_op();
        for effort in [Effort::Quick, Effort::Full] {
            let native = Native::compile_with(&p, effort).expect("compiles");
            equals_the_interpreter(&p, &native);
        }
    }

    fn equals_the_interpreter(p: &Program, native: &Native) {
        for x in [
            [0.3, 1.7],
            [-2.5, 0.9],
            [4.0, 3.0],
            [1e-300, 7e10],
            [f64::NAN, 1.0],
        ] {
            let (mut a, mut b) = ([0.0f64; 2], [0.0f64; 2]);
            let (a0, a1) = a.split_at_mut(1);
            let held_a = native.call([&x[..1], &x[1..]], [a0, a1]).expect("lengths");
            let (b0, b1) = b.split_at_mut(1);
            let held_b = p.eval([&x[..1], &x[1..]], [b0, b1]).expect("lengths");
            assert_eq!(held_a, held_b, "guard at {x:?}");
            assert_eq!(held_a, x[0] < x[1]);
            for (u, v) in a.iter().zip(&b) {
                assert!(u.to_bits() == v.to_bits(), "{u} vs {v} at {x:?}");
            }
        }
    }

    /// More values alive at once than the machine has registers, so that both register
    /// allocators spill: `y_j = Σ_i x_i (x_j + c_ij) / (1 + |x_i − x_j|)` over 40 inputs.
    #[test]
    fn both_efforts_give_the_same_bits_where_values_spill_from_the_registers() {
        const N: u32 = 40;
        let mut ops: Vec<Op> = (0..N).map(|i| Op::Input(1, i)).collect();
        let one = ops.len() as u32;
        ops.push(Op::Const(1.0));
        let mut outputs = Vec::new();
        for j in 0..N {
            let mut sum = None;
            for i in 0..N {
                let at = ops.len() as u32;
                ops.push(Op::Const(0.1 * f64::from(i) - 0.03 * f64::from(j)));
                ops.push(Op::Add(j, at));
                ops.push(Op::Mul(i, at + 1));
                ops.push(Op::Sub(i, j));
                ops.push(Op::Abs(at + 3));
                ops.push(Op::Add(one, at + 4));
                ops.push(Op::Div(at + 2, at + 5));
                let term = at + 6;
                sum = Some(match sum {
                    None => term,
                    Some(s) => {
                        ops.push(Op::Add(s, term));
                        ops.len() as u32 - 1
                    }
                });
            }
            outputs.extend(sum);
        }
        let p = Program {
            inputs: [0, N as usize],
            ops,
            outputs: [outputs, vec![]],
            guards: vec![],
        };
        let x: Vec<f64> = (0..N).map(|i| (f64::from(i) * 0.37).sin() * 3.0).collect();
        let mut want = vec![0.0; N as usize];
        p.eval([&[], &x], [&mut want, &mut []]).expect("lengths");
        for effort in [Effort::Quick, Effort::Full] {
            let native = Native::compile_with(&p, effort).expect("compiles");
            let mut got = vec![0.0; N as usize];
            assert_eq!(native.call([&[], &x], [&mut got, &mut []]), Ok(true));
            for (u, v) in got.iter().zip(&want) {
                assert!(u.to_bits() == v.to_bits(), "{effort:?}: {u} vs {v}");
            }
        }
    }

    #[test]
    fn every_kind_of_guard_outcome_is_checked() {
        for (outcome, x, holds) in [
            (Some(Ordering::Equal), [2.0, 2.0], true),
            (Some(Ordering::Equal), [2.0, 3.0], false),
            (Some(Ordering::Greater), [3.0, 2.0], true),
            (Some(Ordering::Greater), [2.0, 2.0], false),
            (None, [f64::NAN, 2.0], true),
            (None, [1.0, 2.0], false),
        ] {
            let p = Program {
                inputs: [2, 0],
                ops: vec![Op::Input(0, 0), Op::Input(0, 1)],
                outputs: [vec![], vec![]],
                guards: vec![Guard {
                    a: 0,
                    b: 1,
                    outcome,
                }],
            };
            let native = Native::compile(&p).expect("compiles");
            assert_eq!(
                native.call([&x, &[]], [&mut [], &mut []]),
                Ok(holds),
                "{outcome:?} at {x:?}"
            );
        }
    }

    #[test]
    fn programs_that_read_what_is_not_there_are_refused() {
        let mut p = every_op();
        p.ops[3] = Op::Add(0, 3);
        assert_eq!(
            Native::compile(&p).err(),
            Some(ProgramError::Operand { op: 3, operand: 3 })
        );
        let mut p = every_op();
        p.ops[1] = Op::Input(1, 1);
        assert!(matches!(
            Native::compile(&p).err(),
            Some(ProgramError::Input { input: 1, .. })
        ));
        let mut p = every_op();
        p.ops[1] = Op::Input(2, 0);
        assert!(matches!(
            Native::compile(&p).err(),
            Some(ProgramError::Input {
                array: 2,
                len: 0,
                ..
            })
        ));
        let mut p = every_op();
        p.outputs[1].push(13);
        assert_eq!(Native::compile(&p).err(), Some(ProgramError::Reference(13)));
    }

    #[test]
    fn the_interpreter_refuses_a_program_that_reads_what_is_not_there() {
        let mut p = every_op();
        p.ops[3] = Op::Add(0, 3);
        let (mut y0, mut y1) = ([0.0], [0.0]);
        assert_eq!(
            p.eval([&[1.0], &[2.0]], [&mut y0, &mut y1]),
            Err(ProgramError::Operand { op: 3, operand: 3 })
        );
        assert!(matches!(
            every_op().eval([&[1.0], &[]], [&mut y0, &mut y1]),
            Err(ProgramError::Lengths(_))
        ));
    }

    #[test]
    fn slices_of_the_wrong_length_are_refused() {
        let native = Native::compile(&every_op()).expect("compiles");
        let e = native
            .call([&[1.0], &[]], [&mut [0.0], &mut [0.0]])
            .expect_err("short input");
        assert_eq!((e.inputs, e.got_inputs), ([1, 1], [1, 0]));
        assert!(native
            .call([&[1.0], &[2.0]], [&mut [0.0; 2], &mut [0.0]])
            .is_err());
    }

    #[test]
    fn a_compiled_program_runs_from_other_threads() {
        let native = std::sync::Arc::new(Native::compile(&every_op()).expect("compiles"));
        let handles: Vec<_> = (0..4)
            .map(|i| {
                let native = native.clone();
                std::thread::spawn(move || {
                    let (mut y0, mut y1) = ([0.0], [0.0]);
                    native
                        .call([&[f64::from(i)], &[2.5]], [&mut y0, &mut y1])
                        .map(|_| [y0[0], y1[0]])
                })
            })
            .collect();
        for (i, h) in handles.into_iter().enumerate() {
            let (mut w0, mut w1) = ([0.0], [0.0]);
            every_op()
                .eval([&[i as f64], &[2.5]], [&mut w0, &mut w1])
                .expect("lengths");
            assert_eq!(h.join().expect("no panic"), Ok([w0[0], w1[0]]));
        }
    }
}
