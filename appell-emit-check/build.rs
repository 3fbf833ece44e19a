//! Generates Rust from the symbolic engine at build time: random expressions
//! (fixed seed) and their x-derivatives, emitted both as one function and as
//! a prepare/body pair, with the values the engine's lowered program gives at
//! fixed points. The tests then run the compiled code and compare.

use std::fmt::Write;

use appell_symbolic::{EmitOptions, Graph, Id, Program, Symbol, SymbolKind};

const CASES: usize = 200;
const POINTS: usize = 6;

/// xorshift64*: a tiny deterministic generator (no dependency needed).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

struct Syms {
    all: Vec<Symbol>,
}

/// A random expression, defined and smooth everywhere (denominators, logs and
/// roots take 1 + e²), mixing parameters (a, b) and state (x, y, z).
fn random(g: &mut Graph, s: &Syms, rng: &mut Rng, depth: u32) -> Id {
    if depth == 0 || rng.below(7) == 0 {
        return leaf(g, s, rng);
    }
    let d = Draw {
        s,
        depth,
        one: g.int(1).unwrap(),
    };
    match rng.below(24) {
        k @ 0..=6 => arithmetic(g, rng, &d, k),
        k @ 7..=19 => elementary(g, rng, &d, k),
        k => branching(g, rng, &d, k),
    }
}

/// A symbol or a number.
fn leaf(g: &mut Graph, s: &Syms, rng: &mut Rng) -> Id {
    match rng.below(8) {
        0..=4 => g.sym(s.all[rng.below(5) as usize]).unwrap(),
        5 => g.int(rng.below(9) as i64 - 4).unwrap(),
        6 => g
            .rational(rng.below(11) as i64 - 5, rng.below(4) as i64 + 1)
            .unwrap(),
        _ => g.float(rng.uniform(-3.0, 3.0)).unwrap(),
    }
}

/// How a node `depth` deep draws its operands.
struct Draw<'a> {
    s: &'a Syms,
    depth: u32,
    one: Id,
}

impl Draw<'_> {
    /// An operand one level down.
    fn sub(&self, g: &mut Graph, rng: &mut Rng) -> Id {
        random(g, self.s, rng, self.depth - 1)
    }

    /// 1 + e², for e one level down: a safe denominator, log or root.
    fn safe(&self, g: &mut Graph, rng: &mut Rng) -> Id {
        let a = self.sub(g, rng);
        let a2 = g.powi(a, 2).unwrap();
        g.add(self.one, a2).unwrap()
    }
}

/// Sums, differences, products, quotients and integer powers (`k` in 0..=6).
fn arithmetic(g: &mut Graph, rng: &mut Rng, d: &Draw, k: u64) -> Id {
    match k {
        0 | 1 => {
            let (a, b) = (d.sub(g, rng), d.sub(g, rng));
            g.add(a, b).unwrap()
        }
        2 => {
            let (a, b) = (d.sub(g, rng), d.sub(g, rng));
            g.sub(a, b).unwrap()
        }
        3 | 4 => {
            let (a, b) = (d.sub(g, rng), d.sub(g, rng));
            g.mul(a, b).unwrap()
        }
        5 => {
            let a = d.sub(g, rng);
            let den = d.safe(g, rng);
            g.div(a, den).unwrap()
        }
        _ => {
            let a = d.sub(g, rng);
            g.powi(a, rng.below(5) as i64).unwrap()
        }
    }
}

/// The elementary functions, each inside its domain (`k` in 7..=19).
fn elementary(g: &mut Graph, rng: &mut Rng, d: &Draw, k: u64) -> Id {
    match k {
        7 => {
            let a = d.sub(g, rng);
            g.sin(a).unwrap()
        }
        8 => {
            let a = d.sub(g, rng);
            g.cos(a).unwrap()
        }
        9 => {
            let a = d.sub(g, rng);
            let s = g.sin(a).unwrap();
            g.tan(s).unwrap()
        }
        10 => {
            let a = d.sub(g, rng);
            let s = g.sin(a).unwrap();
            g.exp(s).unwrap()
        }
        11 => {
            let den = d.safe(g, rng);
            g.ln(den).unwrap()
        }
        12 => {
            let den = d.safe(g, rng);
            g.sqrt(den).unwrap()
        }
        13 => {
            let a = d.sub(g, rng);
            let den = d.safe(g, rng);
            g.atan2(a, den).unwrap()
        }
        14 => {
            // A large power, emitted as powi.
            let den = d.safe(g, rng);
            g.powi(den, -(65 + rng.below(3) as i64)).unwrap()
        }
        15 => {
            let a = d.sub(g, rng);
            g.tanh(a).unwrap()
        }
        16 => {
            let a = d.sub(g, rng);
            let s = g.sin(a).unwrap();
            if rng.below(2) == 0 {
                g.sinh(s).unwrap()
            } else {
                g.cosh(s).unwrap()
            }
        }
        17 => {
            // asin and acos of sin(a)/2, inside their domain.
            let a = d.sub(g, rng);
            let s = g.sin(a).unwrap();
            let half = g.rational(1, 2).unwrap();
            let h = g.mul(half, s).unwrap();
            if rng.below(2) == 0 {
                g.asin(h).unwrap()
            } else {
                g.acos(h).unwrap()
            }
        }
        18 => {
            let a = d.sub(g, rng);
            g.atan(a).unwrap()
        }
        _ => {
            let den = d.safe(g, rng);
            let b = d.sub(g, rng);
            let s = g.sin(b).unwrap();
            g.powf(den, s).unwrap()
        }
    }
}

/// Selections, minima and maxima, and signs (`k` in 20..=23).
fn branching(g: &mut Graph, rng: &mut Rng, d: &Draw, k: u64) -> Id {
    match k {
        20 => {
            let (c, a, b) = (d.sub(g, rng), d.sub(g, rng), d.sub(g, rng));
            g.select(c, a, b).unwrap()
        }
        21 => {
            let (a, b) = (d.sub(g, rng), d.sub(g, rng));
            if rng.below(2) == 0 {
                g.min(a, b).unwrap()
            } else {
                g.max(a, b).unwrap()
            }
        }
        _ => {
            let (a, b) = (d.sub(g, rng), d.sub(g, rng));
            let s = g.signum(a).unwrap();
            g.mul(s, b).unwrap()
        }
    }
}

fn main() {
    let out_dir = std::env::var("OUT_DIR").expect("OUT_DIR");
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let mut code = String::new();
    let mut table = String::from(
        "// Values computed by the engine; some equal well-known constants.\n#[allow(clippy::approx_constant)]\npub static CASES: &[Case] = &[\n",
    );
    let names = ["a", "b", "x", "y", "z"];
    let params: Vec<String> = names[..2].iter().map(|s| s.to_string()).collect();
    let state: Vec<String> = names[2..].iter().map(|s| s.to_string()).collect();
    let all: Vec<String> = names.iter().map(|s| s.to_string()).collect();
    for k in 0..CASES {
        let mut g = Graph::new();
        let syms = Syms {
            all: vec![
                g.parameter("a").unwrap(),
                g.parameter("b").unwrap(),
                g.declare("x", SymbolKind::Auxiliary).unwrap(),
                g.declare("y", SymbolKind::Auxiliary).unwrap(),
                g.declare("z", SymbolKind::Auxiliary).unwrap(),
            ],
        };
        let e = random(&mut g, &syms, &mut rng, 5);
        let dx = g.diff(e, syms.all[2]).unwrap();
        let program = Program::lower(&g, &[e, dx]);
        let rust = program.to_rust(&g, &EmitOptions::default());
        code.push_str(&rust.function(&format!("joint_{k}"), "::appell_core::Scalar", &all));
        let fused = program.to_rust(
            &g,
            &EmitOptions {
                fused: true,
                ..EmitOptions::default()
            },
        );
        let fused_fn = fused.function(&format!("fused_{k}"), "::appell_core::Scalar", &all);
        code.push_str(&fused_fn);
        code.push_str(&rust.split_functions(
            &format!("split_{k}"),
            "::appell_core::Scalar",
            &params,
            &state,
        ));
        let mut points = String::new();
        for _ in 0..POINTS {
            let p: Vec<f64> = (0..5).map(|_| rng.uniform(-2.0, 2.0)).collect();
            let v = program
                .eval(&|s| syms.all.iter().position(|t| *t == s).map(|i| p[i]))
                .unwrap();
            let _ = write!(
                points,
                "([{:?}, {:?}, {:?}, {:?}, {:?}], [{:?}, {:?}]), ",
                p[0], p[1], p[2], p[3], p[4], v[0], v[1]
            );
        }
        let _ = writeln!(
            table,
            "    Case {{ text: {:?}, ops: {}, powi: {}, fused_text: {}, joint_f64: joint_{k}::<f64>, joint_f32: joint_{k}::<f32>, \
             joint_dual: joint_{k}::<num_dual::Dual64>, fused_f64: fused_{k}::<f64>, \
             split: |p, s| {{ let h = split_{k}_prepare::<f64>(p[0], p[1]); split_{k}(&h, p[0], p[1], s[0], s[1], s[2]) }}, \
             points: &[{points}] }},",
            g.display(e).to_string(),
            rust.ops.total() + rust.prepare_ops.total(),
            rust.ops.powi + rust.prepare_ops.powi > 0,
            fused_fn.contains(".fma("),
        );
    }
    table.push_str("];\n");
    std::fs::write(format!("{out_dir}/generated.rs"), code).unwrap();
    std::fs::write(format!("{out_dir}/cases.rs"), table).unwrap();
    println!("cargo:rerun-if-changed=build.rs");
}
