//! Stage 4: the `Model` implementation, as Rust text parsed into tokens.
//!
//! Every numeric function is one straight-line program lowered by the engine
//! (shared subexpressions bound once), generic over the scalar `__T`. The
//! reduced rhs reads parameter-only values from `Prepared`, computed once
//! per parameter set, and solves Appell's equations by an unrolled LDLᵀ
//! factorization. Paths go through `::appell::__private`; everything is
//! wrapped in `const _: () = { ... };`.

use std::fmt::Write;
use std::str::FromStr;

use appell_symbolic::{EmitOptions, Id, Program, RustCode, Symbol, SymbolKind};
use proc_macro2::TokenStream;

use crate::derivation::{singleton_rows, Derivation, Elimination, RowSource, SingletonOrder};

const P: &str = "::appell::__private";

fn options(hoist: bool) -> EmitOptions {
    EmitOptions {
        scalar: "__T".into(),
        constant: format!("<__T as {P}::Scalar>::from_f64({{lit}})"),
        cse: true,
        hoist_parameters: hoist,
        symbol_text: Default::default(),
        symbol_stage: Default::default(),
        fused: true,
    }
}

fn f64_options() -> EmitOptions {
    EmitOptions {
        scalar: "f64".into(),
        constant: "{lit}_f64".into(),
        cse: true,
        hoist_parameters: false,
        symbol_text: Default::default(),
        symbol_stage: Default::default(),
        fused: false,
    }
}

fn code(d: &Derivation, roots: &[Id], o: &EmitOptions) -> RustCode {
    Program::lower(&d.model.g, roots).to_rust(&d.model.g, o)
}

/// Statements (prepare and body) of a code block, indented.
fn statements(c: &RustCode) -> String {
    let mut s = String::new();
    for st in c.prepare.iter().chain(&c.body) {
        let _ = writeln!(s, "        {st}");
    }
    s
}

struct Emitter<'a> {
    d: &'a Derivation,
    /// The type the implementation is for.
    type_name: String,
    /// How the parameters are reached (`self`, or `self.0` for a scene).
    this: String,
    /// The name of the `ModelInfo` static.
    info_ident: String,
    /// The scene infos the full model lists (empty for a scene).
    scene_infos: String,
    /// The full model's `scene_rhs` and `visit_scene` (empty for a scene).
    scene_rhs: String,
}

impl Emitter<'_> {
    fn coord(&self, i: usize) -> String {
        self.d.model.coords[i].0.to_string()
    }

    fn params_as(&self, scalar: bool) -> String {
        let mut s = String::new();
        for p in &self.d.model.params {
            let f = &p.ident;
            if scalar {
                let _ = writeln!(
                    s,
                    "        let {f}: __T = <__T as {P}::Scalar>::from_f64({this}.{f});",
                    this = self.this
                );
            } else {
                let _ = writeln!(s, "        let {f}: f64 = {this}.{f};", this = self.this);
            }
        }
        s
    }

    fn positivity(&self) -> String {
        let mut s = String::new();
        for p in self.d.model.params.iter().filter(|p| p.positive) {
            let f = &p.ident;
            let _ = writeln!(
                s,
                "        if !({this}.{f} > 0.0) {{ return {P}::Err({P}::ModelError::NonPositiveParameter {{ name: \"{f}\", value: {this}.{f} }}); }}",
                this = self.this
            );
        }
        s
    }

    fn bind_q(&self, slice: &str) -> String {
        let mut s = String::new();
        for i in 0..self.d.n {
            let _ = writeln!(s, "        let {} = {slice}[{i}];", self.coord(i));
        }
        s
    }

    fn bind_qdot(&self, slice: &str) -> String {
        let mut s = String::new();
        for i in 0..self.d.n {
            let _ = writeln!(s, "        let {}_dot = {slice}[{i}];", self.coord(i));
        }
        s
    }

    fn bind_u(&self, slice: &str) -> String {
        let mut s = String::new();
        for (k, spec) in self.d.model.speed_specs.iter().enumerate() {
            let _ = writeln!(
                s,
                "        let {} = {slice}[{k}];",
                self.d.model.g.symbol_name(spec.symbol)
            );
        }
        s
    }

    fn bind_inputs(&self, slice: &str) -> String {
        let mut s = String::new();
        for (k, (name, _)) in self.d.model.inputs.iter().enumerate() {
            let _ = writeln!(s, "        let {name} = {slice}[{k}];");
        }
        s
    }

    /// Statements returning `NonFinite` naming the first state component,
    /// input or parameter of the rhs that is NaN or infinite.
    fn non_finite_diagnosis(&self) -> String {
        let d = self.d;
        let model = &d.model;
        let mut s = String::new();
        let mut names: Vec<String> = d
            .reduction
            .retained
            .iter()
            .map(|&r| self.coord(r))
            .collect();
        names.extend(model.speed_specs.iter().map(|sp| {
            let name = d.model.g.symbol_name(sp.symbol).to_string();
            match sp.coordinate {
                Some(_) => name,
                None => sp.name.clone(),
            }
        }));
        for (k, name) in names.iter().enumerate() {
            let _ = writeln!(
                s,
                "                if !{P}::Scalar::re(__state[{k}]).is_finite() {{ return {P}::Err({P}::ModelError::NonFinite {{ what: \"state component `{name}`\" }}); }}"
            );
        }
        for (k, (name, _)) in model.inputs.iter().enumerate() {
            let _ = writeln!(
                s,
                "                if !{P}::Scalar::re(__inputs[{k}]).is_finite() {{ return {P}::Err({P}::ModelError::NonFinite {{ what: \"input `{name}`\" }}); }}"
            );
        }
        for p in &model.params {
            let f = &p.ident;
            let _ = writeln!(
                s,
                "                if !{this}.{f}.is_finite() {{ return {P}::Err({P}::ModelError::NonFinite {{ what: \"parameter `{f}`\" }}); }}",
                this = self.this
            );
        }
        // A zero-length `norm`/`unit` argument, where it depends on the
        // retained coordinates and the parameters only (so the state
        // determines it).
        let g = &model.g;
        let retained: Vec<Symbol> = d
            .reduction
            .retained
            .iter()
            .map(|&r| model.coords[r].1.q)
            .collect();
        let checked: Vec<&(Id, String)> = model
            .norms
            .iter()
            .filter(|(n2, _)| {
                g.dependencies(*n2)
                    .iter()
                    .all(|sym| match g.symbol_kind(sym) {
                        SymbolKind::Parameter | SymbolKind::Time => true,
                        SymbolKind::Coordinate => retained.contains(&sym),
                        _ => false,
                    })
                    && !g.is_parameter_only(*n2)
            })
            .collect();
        if !checked.is_empty() {
            let roots: Vec<Id> = checked.iter().map(|(n2, _)| *n2).collect();
            let c = code(d, &roots, &options(false));
            s.push_str("                {\n");
            s.push_str(
                &self
                    .params_as(true)
                    .replace("        let ", "                let "),
            );
            for (k, &r) in d.reduction.retained.iter().enumerate() {
                let _ = writeln!(s, "                let {} = __state[{k}];", self.coord(r));
            }
            for st in c.prepare.iter().chain(&c.body) {
                let _ = writeln!(s, "                {st}");
            }
            for (k, (_, label)) in checked.iter().enumerate() {
                let _ = writeln!(
                    s,
                    "                if !({P}::Scalar::re({}) > 1e-20) {{ return {P}::Err({P}::ModelError::NonFinite {{ what: \"{label} has zero length\" }}); }}",
                    c.outputs[k]
                );
            }
            s.push_str("                }\n");
        }
        s
    }

    fn check(&self, arg: &str, len: usize) -> String {
        format!("        {P}::check_len(\"{arg}\", {arg}, {len})?;\n")
    }

    /// Numeric elimination: solve D' X = R (and D' Ẋ = R' when `rates`),
    /// binding the auxiliary symbols. Returns the text and its op count.
    fn elimination(&self, rates: bool) -> (String, usize) {
        let Elimination::Numeric(ne) = &self.d.elimination else {
            return (String::new(), 0);
        };
        let (m, l) = (ne.k, self.d.l);
        let mut s = String::new();
        let mut ops = 0;
        let mut stage = |s: &mut String, rhs: &[Id], width: usize, tag: &str| {
            let mut roots: Vec<Id> = ne.dp.clone();
            roots.extend_from_slice(rhs);
            let c = code(self.d, &roots, &options(false));
            ops += c.ops.total() + m * m * m + m * m * width * 2;
            s.push_str("        {\n");
            s.push_str(
                &statements(&c)
                    .replace("\n        ", "\n            ")
                    .replacen("        ", "            ", 1),
            );
            let rows: Vec<String> = (0..m)
                .map(|i| {
                    format!(
                        "[{}]",
                        (0..m)
                            .map(|j| c.outputs[i * m + j].clone())
                            .collect::<Vec<_>>()
                            .join(", ")
                    )
                })
                .collect();
            let rrows: Vec<String> = (0..m)
                .map(|i| {
                    format!(
                        "[{}]",
                        (0..width)
                            .map(|j| c.outputs[m * m + i * width + j].clone())
                            .collect::<Vec<_>>()
                            .join(", ")
                    )
                })
                .collect();
            let _ = writeln!(
                s,
                "            let mut __a{tag}: [[__T; {m}]; {m}] = [{}];",
                rows.join(", ")
            );
            let _ = writeln!(
                s,
                "            let mut __b{tag}: [[__T; {width}]; {m}] = [{}];",
                rrows.join(", ")
            );
            let _ = writeln!(
                s,
                "            {P}::lu_solve(&mut __a{tag}, &mut __b{tag})?;"
            );
            let _ = writeln!(s, "            __x{tag} = __b{tag};");
            s.push_str("        }\n");
        };
        let cols = &ne.columns;
        let _ = writeln!(s, "        let __x0: [[__T; {}]; {m}];", cols.len());
        let rhs: Vec<Id> = (0..m)
            .flat_map(|i| cols.iter().map(move |&j| ne.rhs[i * (l + 1) + j]))
            .collect();
        stage(&mut s, &rhs, cols.len(), "0");
        for i in 0..m {
            for (c, j) in cols.iter().enumerate() {
                let _ = writeln!(s, "        let __x_{i}_{j} = __x0[{i}][{c}];");
            }
        }
        if rates {
            let _ = writeln!(s, "        let __x1: [[__T; 1]; {m}];");
            stage(&mut s, &ne.rhs_rate, 1, "1");
            for i in 0..m {
                let _ = writeln!(s, "        let __w_{i} = __x1[{i}][0];");
            }
        }
        (s, ops)
    }

    /// The rhs as one program sharing every common subexpression: with a
    /// numeric elimination, S and R first (stage 0), S factored once and X
    /// solved, then (Ṙ − Ṡ X)[ẏ; 1] (stage 1) and w from the same factors,
    /// then `roots` (stage 2). Returns the code (outputs: `roots` only), the
    /// statements with the solves between the stages, and the solves'
    /// operation count.
    fn staged_rhs(&self, roots: &[Id]) -> (RustCode, String, usize) {
        let d = self.d;
        let indent = |s: &mut String, v: &[String]| {
            for st in v {
                let _ = writeln!(s, "        {st}");
            }
        };
        let Elimination::Numeric(ne) = &d.elimination else {
            let c = code(d, roots, &options(true));
            let mut text = String::new();
            indent(&mut text, &c.body);
            return (c, text, 0);
        };
        let (m, l) = (ne.k, d.l);
        let cols = &ne.columns;
        let mut all: Vec<Id> = ne.dp.clone();
        for i in 0..m {
            all.extend(cols.iter().map(|&j| ne.rhs[i * (l + 1) + j]));
        }
        all.extend(&ne.rhs_rate);
        let head = all.len();
        all.extend(roots);
        let mut o = options(true);
        for &x in &ne.x {
            o.symbol_stage.insert(x, 1);
        }
        for &w in &ne.w {
            o.symbol_stage.insert(w, 2);
        }
        let mut c = code(d, &all, &o);
        let eo: Vec<String> = c.outputs.drain(..head).collect();
        let width = cols.len();
        let matrix = |offset: usize, w: usize| -> String {
            let rows: Vec<String> = (0..m)
                .map(|i| {
                    let row: Vec<String> = (0..w).map(|j| eo[offset + i * w + j].clone()).collect();
                    format!("[{}]", row.join(", "))
                })
                .collect();
            rows.join(", ")
        };
        // Rows of S with a single entry among the unknowns not yet solved
        // are solved one by one, in order (a block lower-triangular part:
        // each such unknown costs a division, and no other entry changes,
        // so there is nothing for pivoting to protect); LU with partial
        // pivoting takes the rest.
        let entry = |i: usize, j: usize| !d.model.g.is_zero(ne.dp[i * m + j]);
        let SingletonOrder {
            peeled,
            rows_left,
            cols_left,
        } = singleton_rows(m, entry);
        let b = rows_left.len();
        let mut s = String::new();
        indent(&mut s, c.stages.first().map_or(&[], |v| v.as_slice()));
        let mut solve_ops = 0;
        // As `lu_factor` and `lu_substitute` count them: the factorization
        // (a reciprocal per column, kept, a multiplier and a multiply-subtract
        // per entry below and right of the pivot), then k(2n² − n) for k
        // right-hand columns (X's, then w's).
        let factor_ops = |n: usize| -> usize {
            (0..n)
                .map(|c| 1 + (n - c - 1) * (1 + 2 * (n - c - 1)))
                .sum()
        };
        let substitute_ops = |n: usize, k: usize| k * (2 * n * n - n);
        let _ = writeln!(
            s,
            "        let __s: [[__T; {m}]; {m}] = [{}];",
            matrix(0, m)
        );
        let _ = writeln!(
            s,
            "        let __x0: [[__T; {width}]; {m}] = [{}];",
            matrix(m * m, width)
        );
        let _ = writeln!(
            s,
            "        let __scale = {P}::constraint_scale(&__s, {P}::max_abs(&__x0))?;"
        );
        for (t, &(i, j)) in peeled.iter().enumerate() {
            let _ = writeln!(s, "        {P}::check_pivot(__s[{i}][{j}], __scale, {j})?;");
            let _ = writeln!(
                s,
                "        let __inv_{t} = <__T as {P}::Scalar>::one() / __s[{i}][{j}];"
            );
            solve_ops += 1;
        }
        // Right sides `rhs` (an array of `w` columns); `name(j, k)` is
        // the solved unknown j's value in column k.
        // `zero(i, k)`: the right side's entry is identically zero. An
        // unknown solved from zeros alone is zero and costs nothing, and
        // no update multiplies by it.
        let solve = |s: &mut String,
                     ops: &mut usize,
                     rhs: &str,
                     w: usize,
                     name: &dyn Fn(usize, usize) -> String,
                     zero: &dyn Fn(usize, usize) -> bool,
                     factor: bool| {
            let mut vanishing = std::collections::HashSet::new();
            for (t, &(i, j)) in peeled.iter().enumerate() {
                for k in 0..w {
                    let mut e = format!("{rhs}[{i}][{k}]");
                    let mut terms = 0;
                    for &(_, jj) in &peeled[..t] {
                        if entry(i, jj) && !vanishing.contains(&(jj, k)) {
                            e = format!("{e} - __s[{i}][{jj}] * {}", name(jj, k));
                            *ops += 2;
                            terms += 1;
                        }
                    }
                    if terms == 0 && zero(i, k) {
                        vanishing.insert((j, k));
                        let _ = writeln!(
                            s,
                            "        let {} = <__T as {P}::Scalar>::zero();",
                            name(j, k)
                        );
                        continue;
                    }
                    let _ = writeln!(s, "        let {} = ({e}) * __inv_{t};", name(j, k));
                    *ops += 1;
                }
            }
            if b == 0 {
                return;
            }
            let rows: Vec<String> = rows_left
                .iter()
                .map(|&r| {
                    let row: Vec<String> = (0..w)
                        .map(|k| {
                            let mut e = format!("{rhs}[{r}][{k}]");
                            for &(_, jj) in &peeled {
                                if entry(r, jj) && !vanishing.contains(&(jj, k)) {
                                    e = format!("{e} - __s[{r}][{jj}] * {}", name(jj, k));
                                    *ops += 2;
                                }
                            }
                            e
                        })
                        .collect();
                    format!("[{}]", row.join(", "))
                })
                .collect();
            let _ = writeln!(
                s,
                "        let mut {rhs}b: [[__T; {w}]; {b}] = [{}];",
                rows.join(", ")
            );
            if factor {
                let block: Vec<String> = rows_left
                    .iter()
                    .map(|&r| {
                        let row: Vec<String> = cols_left
                            .iter()
                            .map(|&c| format!("__s[{r}][{c}]"))
                            .collect();
                        format!("[{}]", row.join(", "))
                    })
                    .collect();
                let columns: Vec<String> = cols_left.iter().map(|c| c.to_string()).collect();
                let _ = writeln!(
                    s,
                    "        let mut __sb: [[__T; {b}]; {b}] = [{}];",
                    block.join(", ")
                );
                // The block's column numbers are S's.
                let _ = writeln!(
                        s,
                        "        let __swaps = match {P}::lu_factor(&mut __sb, __scale) {{ \
                         Ok(swaps) => swaps, \
                         Err({P}::ModelError::SingularConstraints {{ column, pivot }}) => \
                         return Err({P}::ModelError::SingularConstraints {{ column: [{}][column], pivot }}), \
                         Err(e) => return Err(e) }};",
                        columns.join(", ")
                    );
                *ops += factor_ops(b);
            }
            let _ = writeln!(
                s,
                "        {P}::lu_substitute(&__sb, &__swaps, &mut {rhs}b);"
            );
            *ops += substitute_ops(b, w);
            for (q, &c) in cols_left.iter().enumerate() {
                for k in 0..w {
                    let _ = writeln!(s, "        let {} = {rhs}b[{q}][{k}];", name(c, k));
                }
            }
        };
        let x_name = |j: usize, k: usize| format!("__x_{j}_{}", cols[k]);
        let rhs_zero = |i: usize, k: usize| d.model.g.is_zero(ne.rhs[i * (l + 1) + cols[k]]);
        solve(
            &mut s,
            &mut solve_ops,
            "__x0",
            width,
            &x_name,
            &rhs_zero,
            true,
        );
        indent(&mut s, c.stages.get(1).map_or(&[], |v| v.as_slice()));
        let _ = writeln!(
            s,
            "        let __x1: [[__T; 1]; {m}] = [{}];",
            matrix(m * m + m * width, 1)
        );
        let w_name = |j: usize, _k: usize| format!("__w_{j}");
        solve(
            &mut s,
            &mut solve_ops,
            "__x1",
            1,
            &w_name,
            &|_, _| false,
            false,
        );
        indent(&mut s, c.stages.get(2).map_or(&[], |v| v.as_slice()));
        c.body.clear();
        (c, s, solve_ops)
    }

    /// Unrolled LDLᵀ factorization of M (lower triangle given as
    /// expressions): binds `__l_i_j` and `__d_j`, checking each pivot against
    /// `__tol` when `checks`.
    fn ldlt_factor(&self, m: &[String], checks: bool) -> (String, usize) {
        let l = self.d.l;
        let mut s = String::new();
        let mut ops = 0;
        for i in 0..l {
            for j in 0..=i {
                let _ = writeln!(s, "        let __m_{i}_{j} = {};", m[i * l + j]);
            }
        }
        let diag: Vec<String> = (0..l)
            .map(|i| format!("{P}::Scalar::re(__m_{i}_{i}).abs()"))
            .collect();
        let _ = writeln!(
            s,
            "        let __tol = 1e-13 * {};",
            if l == 1 {
                diag[0].clone()
            } else {
                format!(
                    "[{}].iter().fold(0.0f64, |a, b| a.max(*b))",
                    diag.join(", ")
                )
            }
        );
        // `__e_i_j` = l_ij d_j, kept before the division: each update is then
        // one product, l_ik (l_jk d_k) = l_ik e_jk.
        for j in 0..l {
            let mut e = format!("__m_{j}_{j}");
            for k in 0..j {
                e.push_str(&format!(" - __l_{j}_{k} * __e_{j}_{k}"));
                ops += 2;
            }
            let _ = writeln!(s, "        let __d_{j} = {e};");
            if checks {
                s.push_str(&self.pivot_check(j, "__tol"));
            }
            if self.pivot_reciprocal(j) {
                let _ = writeln!(
                    s,
                    "        let __r_{j} = <__T as {P}::Scalar>::one() / __d_{j};"
                );
                ops += 1;
            }
            for i in j + 1..l {
                let mut e = format!("__m_{i}_{j}");
                for k in 0..j {
                    e.push_str(&format!(" - __l_{i}_{k} * __e_{j}_{k}"));
                    ops += 2;
                }
                let _ = writeln!(s, "        let __e_{i}_{j} = {e};");
                let _ = writeln!(
                    s,
                    "        let __l_{i}_{j} = {};",
                    self.over_pivot(&format!("__e_{i}_{j}"), j)
                );
                ops += 1;
            }
        }
        (s, ops)
    }

    /// Whether the factorization keeps 1/d_j (`__r_j`) and multiplies by
    /// it. A pivot that divides two values or more (every pivot but the
    /// last: a multiplier l_ij and the solve's w_j) then costs one division
    /// and products, which a divider that is not pipelined runs much faster
    /// (the 8-link pendulum's rhs about 10% faster, the double pendulum's
    /// 8%). The last pivot divides w only, so it keeps its division, except
    /// with a numeric elimination: M needs the dependent rates X but not
    /// their acceleration remainder w, and f needs both, so M is complete
    /// long before f, the division runs while f is computed, and the
    /// substitution that waits on f multiplies (about 4 cycles) instead of
    /// dividing (about 14): the bicycle's rhs 1.5–2% faster natively than
    /// with that division kept, and 3–5% faster than with none kept. With a
    /// constant M the factors are computed once per parameter set, so every
    /// reciprocal is kept there and the rhs divides by no pivot.
    fn pivot_reciprocal(&self, j: usize) -> bool {
        j + 1 < self.d.l
            || matches!(self.d.elimination, Elimination::Numeric(_))
            || self.constant_mass()
    }

    /// Whether M depends on parameters only: its factorization then moves
    /// into `prepare`, and the rhs keeps only the two triangular solves.
    fn constant_mass(&self) -> bool {
        let d = self.d;
        d.l > 0
            && d.equations
                .mass
                .iter()
                .all(|&e| d.model.g.is_parameter_only(e))
    }

    /// `value / d_j`, as a product with `__r_j` when it is kept.
    fn over_pivot(&self, value: &str, j: usize) -> String {
        if self.pivot_reciprocal(j) {
            format!("{value} * __r_{j}")
        } else {
            format!("{value} / __d_{j}")
        }
    }

    fn pivot_check(&self, j: usize, tol: &str) -> String {
        format!(
            "        if !({P}::Scalar::re(__d_{j}) > {tol}) {{ return {P}::Err({P}::ModelError::SingularMassMatrix {{ index: {j}, pivot: {P}::Scalar::re(__d_{j}) }}); }}\n"
        )
    }

    /// Forward and back substitution with the factors: binds `__y_k` = ÿ_k.
    fn ldlt_solve(&self, f: &[String]) -> (String, usize) {
        let l = self.d.l;
        let mut s = String::new();
        let mut ops = 0;
        for i in 0..l {
            let mut e = format!("({})", f[i]);
            for k in 0..i {
                e.push_str(&format!(" - __l_{i}_{k} * __z_{k}"));
                ops += 2;
            }
            let _ = writeln!(s, "        let __z_{i} = {e};");
        }
        for i in 0..l {
            let _ = writeln!(
                s,
                "        let __w_{i} = {};",
                self.over_pivot(&format!("__z_{i}"), i)
            );
            ops += 1;
        }
        for i in (0..l).rev() {
            let mut e = format!("__w_{i}");
            for k in i + 1..l {
                e.push_str(&format!(" - __l_{k}_{i} * __y_{k}"));
                ops += 2;
            }
            let _ = writeln!(s, "        let __y_{i} = {e};");
        }
        (s, ops)
    }

    /// Names of the factors kept in `Prepared` when M is constant.
    fn factor_names(&self) -> Vec<String> {
        let l = self.d.l;
        let mut v = Vec::new();
        for i in 0..l {
            for j in 0..i {
                v.push(format!("__l_{i}_{j}"));
            }
        }
        for j in 0..l {
            v.push(format!("__d_{j}"));
        }
        for j in (0..l).filter(|&j| self.pivot_reciprocal(j)) {
            v.push(format!("__r_{j}"));
        }
        v.push("__tolv".into());
        v
    }

    fn info(&self, rhs_ops: appell_symbolic::OpCount, extra_ops: usize) -> String {
        let d = self.d;
        let model = &d.model;
        let list = |v: Vec<String>| {
            format!(
                "&[{}]",
                v.iter()
                    .map(|s| format!("{s:?}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        };
        let coords = |idx: &[usize]| list(idx.iter().map(|&i| self.coord(i)).collect());
        let bodies: Vec<String> = model
            .bodies
            .iter()
            .map(|b| {
                format!(
                    "{P}::BodyInfo {{ name: {:?}, rigid: {} }}",
                    b.name,
                    b.frame.is_some()
                )
            })
            .collect();
        format!(
            "{P}::ModelInfo {{
            name: {name:?},
            parameters: {params},
            coordinates: {all},
            speeds: {speeds},
            dependent: {dependent},
            cyclic: {cyclic},
            ignorable: {ignorable},
            retained: {retained},
            inputs: {inputs},
            effects: {effects},
            outputs: {outputs},
            holonomic: {holo},
            constraints: {m},
            row_sources: &[{row_sources}],
            contacts: &[{contacts}],
            bodies: &[{bodies}],
            force_points: {nf},
            torques: {nt},
            symbolic_elimination: {symbolic},
            rhs_ops: {P}::OpCounts {{ add: {add}, mul: {mul}, div: {div}, calls: {calls}, total: {total} }},
            equations: {text:?},
        }}",
            name = model.info_name,
            params = list(model.params.iter().map(|p| p.ident.to_string()).collect()),
            all = coords(&(0..d.n).collect::<Vec<_>>()),
            speeds = list(model.speed_specs.iter().map(|sp| sp.name.clone()).collect()),
            dependent = coords(&d.speeds.dependent),
            cyclic = coords(&d.reduction.cyclic),
            ignorable = coords(&d.reduction.ignorable),
            retained = coords(&d.reduction.retained),
            inputs = list(model.inputs.iter().map(|(i, _)| i.to_string()).collect()),
            effects = list(model.effects.clone()),
            outputs = list(model.outputs.clone()),
            row_sources = d
                .constraints.sources
                .iter()
                .map(|r| match r {
                    RowSource::Holonomic(i) => format!("{P}::RowSource::Holonomic {{ index: {i} }}"),
                    RowSource::Nonholonomic(i) => {
                        format!("{P}::RowSource::Nonholonomic {{ index: {i} }}")
                    }
                    RowSource::Rolling { contact, direction } => format!(
                        "{P}::RowSource::Rolling {{ contact: {contact}, direction: {direction} }}"
                    ),
                })
                .collect::<Vec<_>>()
                .join(", "),
            contacts = model
                .rolling
                .iter()
                .map(|r| format!(
                    "{P}::ContactInfo {{ body: {}, point: {:?}, along: {} }}",
                    r.body,
                    r.point,
                    r.along.is_some()
                ))
                .collect::<Vec<_>>()
                .join(", "),
            holo = d.constraints.holonomic.len(),
            m = d.m,
            bodies = bodies.join(", "),
            nf = model.forces.len(),
            nt = model.torques.len(),
            symbolic = matches!(d.elimination, Elimination::Symbolic),
            add = rhs_ops.add,
            mul = rhs_ops.mul,
            div = rhs_ops.div,
            calls = rhs_ops.calls,
            total = rhs_ops.total() + extra_ops,
            text = d.text,
        )
    }

    fn emit(&self) -> String {
        let d = self.d;
        let model = &d.model;
        let (n, m, l) = (d.n, d.m, d.l);
        let ni = model.inputs.len();
        let np = model.params.len();
        let ns = d.reduction.retained.len() + l;
        let g = &model.g;
        let qdot = &d.map.qdot;

        // --- rhs: M, f and the retained coordinates' rates, hoisted. ---
        let constant_mass = self.constant_mass();
        let mut tri_roots: Vec<Id> = Vec::new();
        for i in 0..l {
            for j in 0..=i {
                tri_roots.push(d.equations.mass[i * l + j]);
            }
        }
        let mut roots: Vec<Id> = if constant_mass {
            Vec::new()
        } else {
            tri_roots.clone()
        };
        roots.extend(&d.equations.forcing);
        for &r in &d.reduction.retained {
            roots.push(qdot[r]);
        }
        let (rhs, rhs_text, elim_ops) = self.staged_rhs(&roots);
        let tri = if constant_mass { 0 } else { l * (l + 1) / 2 };
        let f_text: Vec<String> = rhs.outputs[tri..tri + l].to_vec();
        let mut factor_prepare = String::new();
        let (factor_text, factor_ops, hoisted_names) = if constant_mass {
            let mc = code(d, &tri_roots, &options(false));
            let mut m_text = vec![String::new(); l * l];
            let mut idx = 0;
            for i in 0..l {
                for j in 0..=i {
                    m_text[i * l + j] = mc.outputs[idx].clone();
                    idx += 1;
                }
            }
            let (fac, _) = self.ldlt_factor(&m_text, false);
            let names = self.factor_names();
            let _ = writeln!(
                factor_prepare,
                "        let __factors: [__T; {}] = {{",
                names.len()
            );
            factor_prepare.push_str(&statements(&mc));
            factor_prepare.push_str(&fac);
            let _ = writeln!(
                factor_prepare,
                "        let __tolv = <__T as {P}::Scalar>::from_f64(__tol);"
            );
            let _ = writeln!(factor_prepare, "        [{}]", names.join(", "));
            factor_prepare.push_str("        };\n");
            let mut checks = String::new();
            for j in 0..l {
                checks.push_str(&self.pivot_check(j, &format!("{P}::Scalar::re(__tolv)")));
            }
            let mut all = rhs.hoisted.clone();
            all.extend(names);
            (checks, 0, all)
        } else {
            let mut m_text = vec![String::new(); l * l];
            let mut idx = 0;
            for i in 0..l {
                for j in 0..=i {
                    m_text[i * l + j] = rhs.outputs[idx].clone();
                    idx += 1;
                }
            }
            let (fac, ops) = self.ldlt_factor(&m_text, true);
            (fac, ops, rhs.hoisted.clone())
        };
        let h = hoisted_names.len();
        let (solve_text, solve_ops) = self.ldlt_solve(&f_text);
        let ldlt = format!("{factor_text}{solve_text}");
        let ldlt_ops = factor_ops + solve_ops;
        let mut bind_state = String::new();
        for (k, &r) in d.reduction.retained.iter().enumerate() {
            let _ = writeln!(bind_state, "        let {} = __state[{k}];", self.coord(r));
        }
        for (k, spec) in model.speed_specs.iter().enumerate() {
            let _ = writeln!(
                bind_state,
                "        let {} = __state[{}];",
                g.symbol_name(spec.symbol),
                d.reduction.retained.len() + k
            );
        }
        let mut write_out = String::new();
        for (k, _) in d.reduction.retained.iter().enumerate() {
            let _ = writeln!(
                write_out,
                "        __dstate[{k}] = {};",
                rhs.outputs[tri + l + k]
            );
        }
        for k in 0..l {
            let _ = writeln!(
                write_out,
                "        __dstate[{}] = __y_{k};",
                d.reduction.retained.len() + k
            );
        }
        let mut prepare = String::new();
        for st in &rhs.prepare {
            let _ = writeln!(prepare, "        {st}");
        }
        prepare.push_str(&factor_prepare);
        let prepared_list = {
            let mut v = rhs.hoisted.clone();
            if constant_mass {
                v.extend((0..self.factor_names().len()).map(|i| format!("__factors[{i}]")));
            }
            v.join(", ")
        };
        let hoisted_list = hoisted_names.join(", ");
        let info = self.info(rhs.ops, ldlt_ops + elim_ops);

        // --- mass matrix and forcing ---
        let mut mf_roots = d.equations.mass.clone();
        mf_roots.extend(&d.equations.forcing);
        let mf = code(d, &mf_roots, &options(false));
        let (elim_full, _) = self.elimination(true);
        let (elim_pos, _) = self.elimination(false);

        // --- speed transform, coordinate rates, kinetic energy ---
        let mut ct_roots = d.map.c.clone();
        ct_roots.extend(&d.map.c0);
        let ct = code(d, &ct_roots, &options(false));
        let cr = code(d, qdot, &options(false));
        let ke = code(d, &[d.energies.kinetic], &options(false));
        let pe = code(d, &[d.energies.potential], &options(false));
        let ip = code(d, &[d.energies.input_power], &options(false));
        let mut sd_roots = d.speeds.w.clone();
        sd_roots.extend(&d.speeds.w0);
        let sd = code(d, &sd_roots, &options(false));

        // --- constraint residuals: holonomic f(q,t), rows D q̇ + d ---
        let mut res_roots = d.constraints.holonomic.clone();
        res_roots.extend(&d.velocity_residuals);
        let res = code(d, &res_roots, &options(false));

        // --- kinematic description for the oracle ---
        let mut mp_roots = Vec::new();
        for b in &model.bodies {
            mp_roots.push(b.mass);
            for row in &b.inertia {
                mp_roots.extend(row);
            }
        }
        let mp = code(d, &mp_roots, &f64_options());
        let zero = g
            .lookup(&appell_symbolic::Node::Num(appell_symbolic::Number::ZERO))
            .expect("zero exists");
        let one = g
            .lookup(&appell_symbolic::Node::Num(appell_symbolic::Number::ONE))
            .expect("one exists");
        let identity = [[one, zero, zero], [zero, one, zero], [zero, zero, one]];
        let mut pose_roots = Vec::new();
        for b in &model.bodies {
            pose_roots.extend(b.center);
            let r = b.frame.map(|f| model.frames[f].rot).unwrap_or(identity);
            for row in &r {
                pose_roots.extend(row);
            }
        }
        let poses = code(d, &pose_roots, &options(false));
        let mut rows_roots = d.constraints.d.clone();
        rows_roots.extend(&d.constraints.d0);
        let rows = code(d, &rows_roots, &options(false));
        let mut geo_roots = Vec::new();
        for f in &model.forces {
            geo_roots.extend(f.point);
        }
        for t in &model.torques {
            for row in &model.frames[t.frame].rot {
                geo_roots.extend(row);
            }
        }
        let geo = code(d, &geo_roots, &options(false));
        let mut load_roots = Vec::new();
        for f in &model.forces {
            load_roots.extend(f.vector);
        }
        for t in &model.torques {
            load_roots.extend(t.vector);
        }
        let loads = code(d, &load_roots, &options(false));
        // Contact points, then the direction of every rolling row.
        let nc = model.rolling.len();
        let mut contact_roots = Vec::new();
        for r in &model.rolling {
            contact_roots.extend(r.contact);
        }
        for src in &d.constraints.sources {
            match *src {
                RowSource::Rolling { contact, direction } => match &model.rolling[contact].along {
                    Some(dirs) => contact_roots.extend(dirs[direction]),
                    None => contact_roots.extend(identity[direction]),
                },
                _ => contact_roots.extend([zero; 3]),
            }
        }
        let contacts = code(d, &contact_roots, &options(false));

        let outputs_into = |c: &RustCode, target: &str| -> String {
            let mut s = String::new();
            for (i, o) in c.outputs.iter().enumerate() {
                let _ = writeln!(s, "        {target}[{i}] = {o};");
            }
            s
        };
        let triples_into =
            |c: &RustCode, target: &str, offset: usize, count: usize, width: usize| -> String {
                let mut s = String::new();
                for k in 0..count {
                    let items: Vec<String> = (0..width)
                        .map(|i| c.outputs[offset + k * width + i].clone())
                        .collect();
                    let _ = writeln!(s, "        {target}[{k}] = [{}];", items.join(", "));
                }
                s
            };
        let nb = model.bodies.len();
        let mut poses_out = String::new();
        for k in 0..nb {
            let p: Vec<String> = (0..3).map(|i| poses.outputs[k * 12 + i].clone()).collect();
            let r: Vec<String> = (0..9)
                .map(|i| poses.outputs[k * 12 + 3 + i].clone())
                .collect();
            let _ = writeln!(poses_out, "        __positions[{k}] = [{}];", p.join(", "));
            let _ = writeln!(poses_out, "        __rotations[{k}] = [{}];", r.join(", "));
        }
        let mut mp_out = String::new();
        for k in 0..nb {
            let _ = writeln!(mp_out, "        __masses[{k}] = {};", mp.outputs[k * 10]);
            let r: Vec<String> = (1..10).map(|i| mp.outputs[k * 10 + i].clone()).collect();
            let _ = writeln!(mp_out, "        __inertias[{k}] = [{}];", r.join(", "));
        }
        let nf = model.forces.len();
        let nt = model.torques.len();
        let mut set_param = String::new();
        let mut get_param = String::new();
        for (k, p) in model.params.iter().enumerate() {
            let f = &p.ident;
            let _ = writeln!(
                set_param,
                "            \"{f}\" => {{ {this}.{f} = __value; true }}",
                this = self.this
            );
            let _ = writeln!(
                get_param,
                "        __out[{k}] = {this}.{f};",
                this = self.this
            );
        }
        let params_t = self.params_as(true);
        let params_f = self.params_as(false);
        let pos = self.positivity();
        let finite = (0..ns)
            .map(|k| format!("{P}::Scalar::re(__dstate[{k}]).is_finite()"))
            .collect::<Vec<_>>()
            .join(" && ");
        let finite = if ns == 0 { "true".to_string() } else { finite };

        let info_ident = &self.info_ident;
        let name = &self.type_name;
        let scene_infos = &self.scene_infos;
        let scene_rhs = &self.scene_rhs;
        format!(
            r#"
    static {info_ident}: {P}::ModelInfo = {info};
    #[automatically_derived]
    #[allow(unused_variables, unused_parens, non_snake_case, clippy::all)]
    impl {P}::Model for {name} {{
    type Prepared<__T: {P}::Scalar> = [__T; {h}];
    fn info() -> &'static {P}::ModelInfo {{ &{info_ident} }}
    fn scene_infos() -> &'static [&'static {P}::ModelInfo] {{ {scene_infos} }}
{scene_rhs}
    fn parameter_values(&self, __out: &mut [f64]) -> {P}::Result<(), {P}::ModelError> {{
{chk_out}{get_param}        {P}::Ok(())
    }}
    fn set_parameter(&mut self, __name: &str, __value: f64) -> bool {{
        match __name {{
{set_param}            _ => false,
        }}
    }}
    fn prepare<__T: {P}::Scalar>(&self) -> [__T; {h}] {{
{params_t}{prepare}        [{prepared_list}]
    }}
    fn rhs<__T: {P}::Scalar>(&self, __prepared: &[__T; {h}], t: __T, __state: &[__T], __inputs: &[__T], __dstate: &mut [__T]) -> {P}::Result<(), {P}::ModelError> {{
{chk_state}{chk_inputs}{chk_dstate}{pos}        // The closure reads the prepared values itself: bound outside, each
        // would be captured by reference (an address stored per value and
        // a load through it per use).
        let __result: {P}::Result<(), {P}::ModelError> = (|| {{
        let [{hoisted_list}] = *__prepared;
{params_t}{bind_state}{bind_inputs}{rhs_body}{ldlt}{write_out}        if !({finite}) {{ return {P}::Err({P}::ModelError::NonFinite {{ what: "the state derivative" }}); }}
        {P}::Ok(())
        }})();
        match __result {{
            {P}::Ok(()) => {P}::Ok(()),
            // On the cold path only: a NaN or infinite state, input or
            // parameter is named rather than the symptom it caused.
            {P}::Err(__e) => {{
{diagnose}                {P}::Err(__e)
            }}
        }}
    }}
    fn mass_matrix_and_forcing<__T: {P}::Scalar>(&self, t: __T, __q: &[__T], __u: &[__T], __inputs: &[__T], __m: &mut [__T], __f: &mut [__T]) -> {P}::Result<(), {P}::ModelError> {{
{chk_q}{chk_u}{chk_inputs}{chk_m}{chk_f}{pos}{params_t}{bind_q}{bind_u}{bind_inputs}{elim_full}{mf_body}{mf_out}        {P}::Ok(())
    }}
    fn speed_transform<__T: {P}::Scalar>(&self, t: __T, __q: &[__T], __c: &mut [__T], __c0: &mut [__T]) -> {P}::Result<(), {P}::ModelError> {{
{chk_q}{chk_c}{chk_c0}{pos}{params_t}{bind_q}{elim_pos}{ct_body}{ct_out}        {P}::Ok(())
    }}
    fn coordinate_rates<__T: {P}::Scalar>(&self, t: __T, __q: &[__T], __u: &[__T], __qdot: &mut [__T]) -> {P}::Result<(), {P}::ModelError> {{
{chk_q}{chk_u}{chk_qdot}{pos}{params_t}{bind_q}{bind_u}{elim_pos}{cr_body}{cr_out}        {P}::Ok(())
    }}
    fn constraint_residuals<__T: {P}::Scalar>(&self, t: __T, __q: &[__T], __qdot: &[__T], __holonomic: &mut [__T], __velocity: &mut [__T]) -> {P}::Result<(), {P}::ModelError> {{
{chk_q}{chk_qdot_in}{chk_hol}{chk_vel}{params_t}{bind_q}{bind_qdot}{res_body}{res_out}        {P}::Ok(())
    }}
    fn speed_definitions<__T: {P}::Scalar>(&self, t: __T, __q: &[__T], __w: &mut [__T], __w0: &mut [__T]) -> {P}::Result<(), {P}::ModelError> {{
{chk_q}{chk_w}{chk_w0}{params_t}{bind_q}{sd_body}{sd_out}        {P}::Ok(())
    }}
    fn input_power<__T: {P}::Scalar>(&self, t: __T, __q: &[__T], __u: &[__T], __inputs: &[__T]) -> {P}::Result<__T, {P}::ModelError> {{
{chk_q}{chk_u}{chk_inputs}{params_t}{bind_q}{bind_u}{bind_inputs}{elim_pos}{ip_body}        {P}::Ok({ip_out})
    }}
    fn potential_energy<__T: {P}::Scalar>(&self, t: __T, __q: &[__T]) -> {P}::Result<__T, {P}::ModelError> {{
{chk_q}{params_t}{bind_q}{pe_body}        {P}::Ok({pe_out})
    }}
    fn kinetic_energy<__T: {P}::Scalar>(&self, t: __T, __q: &[__T], __u: &[__T]) -> {P}::Result<__T, {P}::ModelError> {{
{chk_q}{chk_u}{pos}{params_t}{bind_q}{bind_u}{elim_pos}{ke_body}        {P}::Ok({ke_out})
    }}
    fn mass_properties(&self, __masses: &mut [f64], __inertias: &mut [[f64; 9]]) -> {P}::Result<(), {P}::ModelError> {{
{chk_masses}{chk_inertias}{params_f}{mp_body}{mp_out}        {P}::Ok(())
    }}
    fn body_poses<__T: {P}::Scalar>(&self, t: __T, __q: &[__T], __positions: &mut [[__T; 3]], __rotations: &mut [[__T; 9]]) -> {P}::Result<(), {P}::ModelError> {{
{chk_q}{chk_positions}{chk_rotations}{params_t}{bind_q}{poses_body}{poses_out}        {P}::Ok(())
    }}
    fn constraint_rows<__T: {P}::Scalar>(&self, t: __T, __q: &[__T], __d: &mut [__T], __d0: &mut [__T]) -> {P}::Result<(), {P}::ModelError> {{
{chk_q}{chk_d}{chk_d0}{params_t}{bind_q}{rows_body}{rows_out}        {P}::Ok(())
    }}
    fn load_geometry<__T: {P}::Scalar>(&self, t: __T, __q: &[__T], __points: &mut [[__T; 3]], __frames: &mut [[__T; 9]]) -> {P}::Result<(), {P}::ModelError> {{
{chk_q}{chk_points}{chk_frames}{params_t}{bind_q}{geo_body}{geo_points}{geo_frames}        {P}::Ok(())
    }}
    fn contact_geometry<__T: {P}::Scalar>(&self, t: __T, __q: &[__T], __points: &mut [[__T; 3]], __directions: &mut [[__T; 3]]) -> {P}::Result<(), {P}::ModelError> {{
{chk_q}{chk_cpoints}{chk_dirs}{params_t}{bind_q}{contacts_body}{contacts_points}{contacts_dirs}        {P}::Ok(())
    }}
    fn load_values<__T: {P}::Scalar>(&self, t: __T, __q: &[__T], __qdot: &[__T], __inputs: &[__T], __forces: &mut [[__T; 3]], __torques: &mut [[__T; 3]]) -> {P}::Result<(), {P}::ModelError> {{
{chk_q}{chk_qdot_in}{chk_inputs}{chk_forces}{chk_torques}{params_t}{bind_q}{bind_qdot}{bind_inputs}{loads_body}{loads_forces}{loads_torques}        {P}::Ok(())
    }}
    }}
"#,
            chk_out = self.check("__out", np),
            chk_state = self.check("__state", ns),
            chk_inputs = self.check("__inputs", ni),
            chk_dstate = self.check("__dstate", ns),
            chk_q = self.check("__q", n),
            chk_u = self.check("__u", l),
            chk_m = self.check("__m", l * l),
            chk_f = self.check("__f", l),
            chk_c = self.check("__c", n * l),
            chk_c0 = self.check("__c0", n),
            chk_qdot = self.check("__qdot", n),
            chk_qdot_in = self.check("__qdot", n),
            chk_hol = self.check("__holonomic", d.constraints.holonomic.len()),
            chk_vel = self.check("__velocity", m),
            chk_w = self.check("__w", l * n),
            chk_w0 = self.check("__w0", l),
            sd_body = statements(&sd),
            sd_out = {
                let mut s = String::new();
                for i in 0..l * n {
                    let _ = writeln!(s, "        __w[{i}] = {};", sd.outputs[i]);
                }
                for i in 0..l {
                    let _ = writeln!(s, "        __w0[{i}] = {};", sd.outputs[l * n + i]);
                }
                s
            },
            chk_masses = self.check("__masses", nb),
            chk_inertias = self.check("__inertias", nb),
            chk_positions = self.check("__positions", nb),
            chk_rotations = self.check("__rotations", nb),
            chk_d = self.check("__d", m * n),
            chk_d0 = self.check("__d0", m),
            chk_points = self.check("__points", nf),
            chk_frames = self.check("__frames", nt),
            chk_forces = self.check("__forces", nf),
            chk_torques = self.check("__torques", nt),
            bind_inputs = self.bind_inputs("__inputs"),
            bind_q = self.bind_q("__q"),
            bind_u = self.bind_u("__u"),
            bind_qdot = self.bind_qdot("__qdot"),
            rhs_body = rhs_text,
            diagnose = self.non_finite_diagnosis(),
            mf_body = statements(&mf),
            mf_out = {
                let mut s = outputs_into(
                    &RustCode {
                        outputs: mf.outputs[..l * l].to_vec(),
                        ..mf.clone()
                    },
                    "__m",
                );
                for k in 0..l {
                    let _ = writeln!(s, "        __f[{k}] = {};", mf.outputs[l * l + k]);
                }
                s
            },
            ct_body = statements(&ct),
            ct_out = {
                let mut s = String::new();
                for i in 0..n * l {
                    let _ = writeln!(s, "        __c[{i}] = {};", ct.outputs[i]);
                }
                for i in 0..n {
                    let _ = writeln!(s, "        __c0[{i}] = {};", ct.outputs[n * l + i]);
                }
                s
            },
            cr_body = statements(&cr),
            cr_out = outputs_into(&cr, "__qdot"),
            res_body = statements(&res),
            res_out = {
                let mut s = String::new();
                let nh = d.constraints.holonomic.len();
                for i in 0..nh {
                    let _ = writeln!(s, "        __holonomic[{i}] = {};", res.outputs[i]);
                }
                for i in 0..m {
                    let _ = writeln!(s, "        __velocity[{i}] = {};", res.outputs[nh + i]);
                }
                s
            },
            ke_body = statements(&ke),
            pe_body = statements(&pe),
            ip_body = statements(&ip),
            ip_out = ip.outputs[0],
            pe_out = pe.outputs[0],
            ke_out = ke.outputs[0],
            mp_body = statements(&mp),
            poses_body = statements(&poses),
            rows_body = statements(&rows),
            rows_out = {
                let mut s = String::new();
                for i in 0..m * n {
                    let _ = writeln!(s, "        __d[{i}] = {};", rows.outputs[i]);
                }
                for i in 0..m {
                    let _ = writeln!(s, "        __d0[{i}] = {};", rows.outputs[m * n + i]);
                }
                s
            },
            geo_body = statements(&geo),
            geo_points = triples_into(&geo, "__points", 0, nf, 3),
            geo_frames = triples_into(&geo, "__frames", nf * 3, nt, 9),
            chk_cpoints = self.check("__points", nc),
            chk_dirs = self.check("__directions", m),
            contacts_body = statements(&contacts),
            contacts_points = triples_into(&contacts, "__points", 0, nc, 3),
            contacts_dirs = triples_into(&contacts, "__directions", nc * 3, m, 3),
            loads_body = statements(&loads),
            loads_forces = triples_into(&loads, "__forces", 0, nf, 3),
            loads_torques = triples_into(&loads, "__torques", nf * 3, nt, 3),
        )
    }
}

/// The `Model` implementations: the full model's, and one per scene on a
/// generated newtype (`{Model}{Scene}(pub Model)`), all in one `const _`
/// block; the scene types are declared beside the struct.
pub fn emit(
    full: &Derivation,
    scenes: &[(syn::Ident, Derivation)],
    vis: &syn::Visibility,
) -> TokenStream {
    let base = full.model.name.to_string();
    let scene_type = |name: &syn::Ident| format!("{base}{}", camel(&name.to_string()));
    let scene_refs: Vec<String> = scenes.iter().map(|(n, _)| format!("&__INFO_{n}")).collect();
    let mut body = format!(
        "    static __SCENES: [&{P}::ModelInfo; {}] = [{}];\n",
        scenes.len(),
        scene_refs.join(", ")
    );
    body.push_str(
        &Emitter {
            d: full,
            type_name: base.clone(),
            this: "self".into(),
            info_ident: "__INFO".into(),
            scene_infos: "&__SCENES".into(),
            scene_rhs: if scenes.is_empty() {
                String::new()
            } else {
                let arms: Vec<String> = scenes
                    .iter()
                    .enumerate()
                    .map(|(i, (n, _))| {
                        format!(
                            "            {i} => {{ let __s = {}::from_ref(self); let __p = {P}::Model::prepare::<f64>(__s); {P}::Model::rhs(__s, &__p, t, __state, __inputs, __dstate) }}",
                            scene_type(n)
                        )
                    })
                    .collect();
                let visits: Vec<String> = scenes
                    .iter()
                    .enumerate()
                    .map(|(i, (n, _))| {
                        format!(
                            "            {i} => {P}::Ok({P}::SceneVisitor::visit(__visitor, {}::from_ref(self))),",
                            scene_type(n)
                        )
                    })
                    .collect();
                format!(
                    "    fn scene_rhs(&self, __scene: usize, t: f64, __state: &[f64], __inputs: &[f64], __dstate: &mut [f64]) -> {P}::Result<(), {P}::ModelError> {{\n        match __scene {{\n{}\n            _ => {P}::Err({P}::ModelError::UnknownScene {{ index: __scene }}),\n        }}\n    }}\n    fn visit_scene<__V: {P}::SceneVisitor>(&self, __scene: usize, __visitor: __V) -> {P}::Result<__V::Output, {P}::ModelError> {{\n        match __scene {{\n{}\n            _ => {P}::Err({P}::ModelError::UnknownScene {{ index: __scene }}),\n        }}\n    }}\n",
                    arms.join("\n"),
                    visits.join("\n")
                )
            },
        }
        .emit(),
    );
    let mut decls = String::new();
    let vis = quote::quote!(#vis).to_string();
    for (name, d) in scenes {
        let ty = scene_type(name);
        let effects = d.model.effects.join(", ");
        let _ = writeln!(
            decls,
            "/// Scene `{name}` of [`{base}`]: the reduced equations with the effects {effects} only (generated by `#[derive(Appell)]`).\n#[repr(transparent)]\n{vis} struct {ty}(pub {base});\n\
             impl {ty} {{\n    /// The model seen as this scene, without a copy.\n    #[allow(unsafe_code)]\n    pub fn from_ref(model: &{base}) -> &Self {{\n        // SAFETY: `{ty}` is a `repr(transparent)` wrapper of `{base}`.\n        unsafe {{ &*(model as *const {base} as *const Self) }}\n    }}\n}}"
        );
        body.push_str(
            &Emitter {
                d,
                type_name: ty,
                this: "self.0".into(),
                info_ident: format!("__INFO_{name}"),
                scene_infos: "&[]".into(),
                scene_rhs: String::new(),
            }
            .emit(),
        );
    }
    let text = format!(
        "{decls}\nconst _: () = {{\n    #[allow(unused_imports)]\n    use {P}::Scalar as _;\n{body}\n}};\n"
    );
    match TokenStream::from_str(&text) {
        Ok(t) => t,
        Err(e) => {
            let msg = format!("appell internal error: generated code does not parse ({e})");
            quote::quote!(compile_error!(#msg);)
        }
    }
}

/// `track_check` → `TrackCheck`.
fn camel(s: &str) -> String {
    s.split('_')
        .filter(|p| !p.is_empty())
        .map(|p| {
            let mut c = p.chars();
            match c.next() {
                Some(f) => f.to_uppercase().collect::<String>() + c.as_str(),
                None => String::new(),
            }
        })
        .collect()
}

/// A stub implementation emitted beside errors, so the user sees only the
/// real ones (thiserror's fallback).
pub fn stub(name: &syn::Ident, scenes: &[syn::Ident], vis: &syn::Visibility) -> TokenStream {
    // The scene types are declared too, so code using them sees only the
    // real errors.
    let vis = quote::quote!(#vis).to_string();
    let mut decls = String::new();
    for sc in scenes {
        let _ = writeln!(
            decls,
            "#[allow(dead_code)]\n{vis} struct {name}{}(pub {name});",
            camel(&sc.to_string())
        );
    }
    let text = decls
        + &format!(
            r#"
const _: () = {{
    static __INFO: {P}::ModelInfo = {P}::ModelInfo {{
        name: "{name}", parameters: &[], coordinates: &[], speeds: &[], dependent: &[], cyclic: &[],
        ignorable: &[], retained: &[], inputs: &[], effects: &[], outputs: &[], holonomic: 0, constraints: 0,
        row_sources: &[], contacts: &[],
        bodies: &[], force_points: 0, torques: 0, symbolic_elimination: true,
        rhs_ops: {P}::OpCounts {{ add: 0, mul: 0, div: 0, calls: 0, total: 0 }}, equations: "",
    }};
    #[allow(unused_variables, clippy::all)]
    impl {P}::Model for {name} {{
        type Prepared<__T: {P}::Scalar> = [__T; 0];
        fn info() -> &'static {P}::ModelInfo {{ &__INFO }}
        fn parameter_values(&self, __out: &mut [f64]) -> {P}::Result<(), {P}::ModelError> {{ ::core::panic!("the model failed to derive; see the compile errors") }}
        fn set_parameter(&mut self, __name: &str, __value: f64) -> bool {{ ::core::panic!("the model failed to derive; see the compile errors") }}
        fn prepare<__T: {P}::Scalar>(&self) -> [__T; 0] {{ ::core::panic!("the model failed to derive; see the compile errors") }}
        fn rhs<__T: {P}::Scalar>(&self, __p: &[__T; 0], t: __T, __s: &[__T], __i: &[__T], __d: &mut [__T]) -> {P}::Result<(), {P}::ModelError> {{ ::core::panic!("the model failed to derive; see the compile errors") }}
        fn mass_matrix_and_forcing<__T: {P}::Scalar>(&self, t: __T, __q: &[__T], __u: &[__T], __i: &[__T], __m: &mut [__T], __f: &mut [__T]) -> {P}::Result<(), {P}::ModelError> {{ ::core::panic!("the model failed to derive; see the compile errors") }}
        fn speed_transform<__T: {P}::Scalar>(&self, t: __T, __q: &[__T], __c: &mut [__T], __c0: &mut [__T]) -> {P}::Result<(), {P}::ModelError> {{ ::core::panic!("the model failed to derive; see the compile errors") }}
        fn coordinate_rates<__T: {P}::Scalar>(&self, t: __T, __q: &[__T], __u: &[__T], __qd: &mut [__T]) -> {P}::Result<(), {P}::ModelError> {{ ::core::panic!("the model failed to derive; see the compile errors") }}
        fn constraint_residuals<__T: {P}::Scalar>(&self, t: __T, __q: &[__T], __qd: &[__T], __h: &mut [__T], __v: &mut [__T]) -> {P}::Result<(), {P}::ModelError> {{ ::core::panic!("the model failed to derive; see the compile errors") }}
        fn kinetic_energy<__T: {P}::Scalar>(&self, t: __T, __q: &[__T], __u: &[__T]) -> {P}::Result<__T, {P}::ModelError> {{ ::core::panic!("the model failed to derive; see the compile errors") }}
        fn mass_properties(&self, __m: &mut [f64], __i: &mut [[f64; 9]]) -> {P}::Result<(), {P}::ModelError> {{ ::core::panic!("the model failed to derive; see the compile errors") }}
        fn body_poses<__T: {P}::Scalar>(&self, t: __T, __q: &[__T], __p: &mut [[__T; 3]], __r: &mut [[__T; 9]]) -> {P}::Result<(), {P}::ModelError> {{ ::core::panic!("the model failed to derive; see the compile errors") }}
        fn constraint_rows<__T: {P}::Scalar>(&self, t: __T, __q: &[__T], __d: &mut [__T], __d0: &mut [__T]) -> {P}::Result<(), {P}::ModelError> {{ ::core::panic!("the model failed to derive; see the compile errors") }}
        fn load_geometry<__T: {P}::Scalar>(&self, t: __T, __q: &[__T], __p: &mut [[__T; 3]], __f: &mut [[__T; 9]]) -> {P}::Result<(), {P}::ModelError> {{ ::core::panic!("the model failed to derive; see the compile errors") }}
        fn load_values<__T: {P}::Scalar>(&self, t: __T, __q: &[__T], __qd: &[__T], __i: &[__T], __f: &mut [[__T; 3]], __t: &mut [[__T; 3]]) -> {P}::Result<(), {P}::ModelError> {{ ::core::panic!("the model failed to derive; see the compile errors") }}
    }}
}};
"#
        );
    TokenStream::from_str(&text).unwrap_or_default()
}
