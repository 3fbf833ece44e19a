//! The codegen stages on token input, without compiling the output.

use appell_codegen::expand;

fn expand_str(src: &str) -> String {
    let input: syn::DeriveInput = syn::parse_str(src).expect("valid Rust");
    expand(&input).to_string()
}

const WHEEL_AXLE: &str = include_str!("../../examples/models/wheel_axle.rs");

/// A model file holds the struct and a Default impl; keep the struct.
fn wheel_axle_struct() -> String {
    model_struct(WHEEL_AXLE)
}

#[test]
fn wheel_axle_expands_without_errors() {
    let out = expand_str(&wheel_axle_struct());
    assert!(!out.contains("compile_error"), "{out}");
    assert!(out.contains("impl :: appell :: __private :: Model for WheelAxle"));
    if std::env::var_os("APPELL_SHOW_EXPANSION").is_some() {
        println!("{out}");
    }
}

#[test]
fn expansion_is_deterministic() {
    let s = wheel_axle_struct();
    assert_eq!(expand_str(&s), expand_str(&s));
}

#[test]
fn several_mistakes_are_reported_together() {
    let out = expand_str(
        r#"
        #[appell(coordinates(q, q), speeds(q))]
        #[appell(particle(P, mass = m))]
        struct Bad { m: f64 }
        "#,
    );
    assert!(out.contains("duplicate coordinate `q`"), "{out}");
    assert!(out.contains("unknown point `P`"), "{out}");
}

#[test]
fn whipple_bicycle_expands() {
    let src = model_struct(include_str!("../../examples/models/whipple_bicycle.rs"));
    let t = std::time::Instant::now();
    let out = expand_str(&src);
    println!(
        "whipple expansion: {:.3} s, {} bytes",
        t.elapsed().as_secs_f64(),
        out.len()
    );
    if let Some(i) = out.find("total :") {
        println!("{}", &out[i..i + 20]);
    }
    if let Some(path) = std::env::var_os("APPELL_WRITE_EXPANSION") {
        std::fs::write(path, &out).unwrap();
    }
    assert!(
        !out.contains("compile_error"),
        "{}",
        &out[..out.len().min(2000)]
    );
}

fn model_struct(src: &str) -> String {
    let start = src.find("#[derive(Appell").expect("derive");
    let end = src.find("impl Default").expect("impl");
    src[start..end].to_string()
}

#[test]
fn ldlt_keeps_a_pivots_reciprocal_where_it_saves_a_division_or_waits_for_f() {
    // No constraints: the first pivot divides l_10 and w_0 and is kept as
    // a reciprocal; the last divides w_1 only and stays a division.
    let out = expand_str(&model_struct(include_str!(
        "../../examples/models/double_pendulum.rs"
    )));
    assert!(out.contains("__l_1_0 = __e_1_0 * __r_0"), "{out}");
    assert!(out.contains("__w_0 = __z_0 * __r_0"), "{out}");
    assert!(out.contains("__w_1 = __z_1 / __d_1"), "{out}");
    assert!(!out.contains("__r_1"), "{out}");
    // A numeric elimination: M is complete before f, so the last pivot's
    // reciprocal is computed early and the solve that waits on f multiplies.
    let out = expand_str(&model_struct(include_str!(
        "../../examples/models/chaplygin_sleigh.rs"
    )));
    assert!(out.contains("__w_1 = __z_1 * __r_1"), "{out}");
    assert!(!out.contains("__z_1 / __d_1"), "{out}");
    // A constant M: the factors, the last pivot's reciprocal among them,
    // are computed in `prepare`, and the rhs divides by no pivot.
    let out = expand_str(&wheel_axle_struct());
    assert!(out.contains("let __r_1 = "), "{out}");
    assert!(out.contains("__w_1 = __z_1 * __r_1"), "{out}");
    assert!(!out.contains("__z_0 / __d_0"), "{out}");
    assert!(!out.contains("__z_1 / __d_1"), "{out}");
}

/// A planar four-bar: crank O–P1, coupler P1–P2, rocker from D = O + d N.x
/// to P3; the loop closes where P2 meets P3.
fn four_bar(closure: &str) -> String {
    format!(
        r#"
        #[appell(coordinates(q1, q2, q3), speeds(q1))]
        #[appell(frame(A = N.rotate_z(q1)), frame(B = N.rotate_z(q2)), frame(C = N.rotate_z(q3)))]
        #[appell(point(P1 = O + l1 * A.x), point(P2 = P1 + l2 * B.x), point(P3 = O + d * N.x + l3 * C.x))]
        #[appell(particle(P1, mass = m1), particle(P2, mass = m2))]
        #[appell(gravity(-g * N.y))]
        {closure}
        struct FourBar {{ m1: f64, m2: f64, l1: f64, l2: f64, l3: f64, d: f64, g: f64 }}
        "#
    )
}

#[test]
fn a_loop_closed_by_two_points_is_its_planar_components() {
    // P2 == P3 gives the N.x and N.y rows (the N.z row is identically zero
    // and dropped): the same equations as the two scalar rows written out.
    let by_points = expand_str(&four_bar("#[appell(holonomic(P2 == P3))]"));
    let by_rows = expand_str(&four_bar(
        "#[appell(holonomic(dot(P2 - P3, N.x) == 0), holonomic(dot(P2 - P3, N.y) == 0))]",
    ));
    assert!(!by_points.contains("compile_error"), "{by_points}");
    assert_eq!(by_points, by_rows);
    // `along` picks the components; the difference can also face `0`.
    let along = expand_str(&four_bar(
        "#[appell(holonomic(P2 - P3 == 0, along = [N.x, N.y]))]",
    ));
    assert_eq!(along, by_rows);
}

#[test]
fn sides_of_different_kinds_are_an_error_that_says_what_to_write() {
    let out = expand_str(&four_bar("#[appell(holonomic(P2 == l1))]"));
    assert!(out.contains("a point and a scalar"), "{out}");
    let out = expand_str(&four_bar("#[appell(holonomic(P2 == P3, along = [N.z]))]"));
    assert!(
        out.contains("identically zero: it constrains nothing"),
        "{out}"
    );
    let out = expand_str(&four_bar("#[appell(holonomic(q1 == q2, along = [N.x]))]"));
    assert!(
        out.contains("`along` is for an equation between points or vectors"),
        "{out}"
    );
}

#[test]
fn a_velocity_equation_between_vectors_is_its_components() {
    // v(P) = ẋ (N.x + N.y + N.z): the N.x row is identically zero and
    // dropped, the others are ẏ = ẋ and ż = ẋ.
    let model = |c: &str| {
        format!(
            r#"
            #[appell(coordinates(x, y, z), speeds(x))]
            #[appell(point(P = O + x * N.x + y * N.y + z * N.z), particle(P, mass = m))]
            {c}
            struct Glide {{ m: f64 }}
            "#
        )
    };
    let by_vectors = expand_str(&model(
        "#[appell(nonholonomic(velocity(P) == dt(x) * (N.x + N.y + N.z)))]",
    ));
    let by_rows = expand_str(&model(
        "#[appell(nonholonomic(dt(y) - dt(x) == 0), nonholonomic(dt(z) - dt(x) == 0))]",
    ));
    assert!(!by_vectors.contains("compile_error"), "{by_vectors}");
    assert!(by_vectors.contains("constraints : 2"), "{by_vectors}");
    assert_eq!(by_vectors, by_rows);
}

#[test]
fn a_chain_of_rotations_is_the_frames_written_one_by_one() {
    // The rolling disc with its yaw, lean and spin frames as one chain: the
    // intermediate frames are named C_1 and C_2 and usable as such.
    let src = model_struct(include_str!("../../examples/models/rolling_disc.rs"));
    let chained = src
        .replace(
            "frame(A = N.rotate_z(yaw)), frame(B = A.rotate_x(lean)), frame(C = B.rotate_y(spin))",
            "frame(C = N.rotate_z(yaw).rotate_x(lean).rotate_y(spin))",
        )
        .replace("r * B.z", "r * C_2.z");
    assert_ne!(chained, src);
    let (a, b) = (expand_str(&src), expand_str(&chained));
    assert!(!b.contains("compile_error"), "{b}");
    assert_eq!(a, b);
    // A chain that does not start from a frame's name says so.
    let bad = src.replace("frame(A = N.rotate_z(yaw))", "frame(A = (N).rotate_z(yaw))");
    assert!(expand_str(&bad).contains("expected the name of the parent frame"));
}
