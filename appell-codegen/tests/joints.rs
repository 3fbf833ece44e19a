//! Joints are the frames, points, coordinates, speeds, inputs and loads
//! they stand for: a mechanism written with joints expands exactly as the
//! same mechanism written with frames and points.

use appell_codegen::{derivation::Options, expand_with, FileRoots};

/// The expansion without the structured form, which only a model written
/// with joints has.
fn expand_str(src: &str) -> String {
    let input: syn::DeriveInput = syn::parse_str(src).expect("valid Rust");
    let closed = Options {
        closed_form_only: true,
        ..Options::default()
    };
    expand_with(&input, &FileRoots::default(), &closed).to_string()
}

fn same_expansion(with_joints: &str, written_out: &str) {
    let (a, b) = (expand_str(with_joints), expand_str(written_out));
    assert!(!a.contains("compile_error"), "{a}");
    assert!(!b.contains("compile_error"), "{b}");
    assert_eq!(a, b);
}

const STRUCT: &str = "struct Arm { m: f64, l: f64, c: f64, g: f64, i1: f64, i2: f64, i3: f64 }";

#[test]
fn a_revolute_chain_is_its_frames_and_points() {
    same_expansion(
        &format!(
            r#"
        #[appell(joint(j1, revolute(z), parent = N, child = L1))]
        #[appell(joint(j2, revolute(y), parent = L1, child = L2, xyz = [0, 0, l]))]
        #[appell(body(b1, center = L1_origin + c * L1.z, frame = L1, mass = m, inertia = principal(i1, i2, i3)))]
        #[appell(body(b2, center = L2_origin + c * L2.z, frame = L2, mass = m, inertia = matrix(i1, i2, i3, 0.01, 0, 0)))]
        #[appell(gravity(-g * N.z))]
        {STRUCT}"#
        ),
        &format!(
            r#"
        #[appell(coordinates(j1, j2), speeds(j1, j2))]
        #[appell(frame(L1 = N.rotate_z(j1)), point(L1_origin = O))]
        #[appell(frame(L2 = L1.rotate_y(j2)), point(L2_origin = L1_origin + l * L1.z))]
        #[appell(point(b1_center = L1_origin + c * L1.z))]
        #[appell(body(b1, center = b1_center, frame = L1, mass = m, inertia = principal(i1, i2, i3)))]
        #[appell(point(b2_center = L2_origin + c * L2.z))]
        #[appell(body(b2, center = b2_center, frame = L2, mass = m, inertia = matrix(i1, i2, i3, 0.01, 0, 0)))]
        #[appell(gravity(-g * N.z))]
        {STRUCT}"#
        ),
    );
}

#[test]
fn an_offset_turned_joint_frame_and_a_general_axis() {
    // URDF's rpy is fixed-axis: R = Rz(yaw) Ry(pitch) Rx(roll), the frame
    // chain yaw, then pitch, then roll about the new axes; zero angles are
    // left out.
    same_expansion(
        &format!(
            r#"
        #[appell(joint(j1, revolute([1, 0, 1]), parent = N, child = L1, xyz = [l, 0, c], rpy = [0.5, 0, 1.5]))]
        #[appell(body(b1, center = L1_origin + c * L1.x, frame = L1, mass = m, inertia = principal(i1, i2, i3)))]
        #[appell(gravity(-g * N.z))]
        {STRUCT}"#
        ),
        &format!(
            r#"
        #[appell(coordinates(j1), speeds(j1))]
        #[appell(frame(j1_frame = N.rotate_z(1.5).rotate_x(0.5)))]
        #[appell(frame(L1 = j1_frame.rotate(1 * j1_frame.x + 1 * j1_frame.z, j1)))]
        #[appell(point(L1_origin = O + (l * N.x + c * N.z)))]
        #[appell(point(b1_center = L1_origin + c * L1.x))]
        #[appell(body(b1, center = b1_center, frame = L1, mass = m, inertia = principal(i1, i2, i3)))]
        #[appell(gravity(-g * N.z))]
        {STRUCT}"#
        ),
    );
}

#[test]
fn prismatic_cylindrical_planar_and_weld_joints() {
    same_expansion(
        &format!(
            r#"
        #[appell(joint(s, prismatic(-y), parent = N, child = C, xyz = [0, 0, l]))]
        #[appell(joint(k, cylindrical(z), parent = C, child = D))]
        #[appell(joint(p, planar(x), parent = D, child = E, xyz = [c, 0, 0]))]
        #[appell(joint(w, weld, parent = E, child = F, xyz = [0, c, 0]))]
        #[appell(body(b, center = F_origin, frame = F, mass = m, inertia = principal(i1, i2, i3)))]
        #[appell(body(d, center = D_origin, frame = D, mass = m, inertia = principal(i1, i2, i3)))]
        #[appell(gravity(-g * N.z))]
        {STRUCT}"#
        ),
        &format!(
            r#"
        #[appell(coordinates(s, k_angle, k_slide, p_x, p_y, p_angle), speeds(s, k_angle, k_slide, p_x, p_y, p_angle))]
        #[appell(frame(C = N), point(C_origin = O + l * N.z + s * -C.y))]
        #[appell(frame(D = C.rotate_z(k_angle)), point(D_origin = C_origin + k_slide * D.z))]
        #[appell(frame(E = D.rotate_x(p_angle)), point(E_origin = D_origin + c * D.x + (p_x * D.y + p_y * D.z)))]
        #[appell(frame(F = E), point(F_origin = E_origin + c * E.y))]
        #[appell(body(b, center = F_origin, frame = F, mass = m, inertia = principal(i1, i2, i3)))]
        #[appell(body(d, center = D_origin, frame = D, mass = m, inertia = principal(i1, i2, i3)))]
        #[appell(gravity(-g * N.z))]
        {STRUCT}"#
        ),
    );
}

#[test]
fn an_actuated_joint_is_an_input_and_a_torque_pair() {
    same_expansion(
        &format!(
            r#"
        #[appell(joint(j1, revolute(z), parent = N, child = L1, actuated))]
        #[appell(joint(j2, revolute(x), parent = L1, child = L2, xyz = [0, 0, l], actuated))]
        #[appell(joint(j3, prismatic(z), parent = L2, child = L3, xyz = [0, c, 0], actuated))]
        #[appell(body(b2, center = L2_origin, frame = L2, mass = m, inertia = principal(i1, i2, i3)))]
        #[appell(body(b3, center = L3_origin, frame = L3, mass = m, inertia = principal(i1, i2, i3)))]
        {STRUCT}"#
        ),
        &format!(
            r#"
        #[appell(coordinates(j1, j2, j3), speeds(j1, j2, j3), inputs(tau_j1, tau_j2, tau_j3))]
        #[appell(frame(L1 = N.rotate_z(j1)), point(L1_origin = O))]
        #[appell(torque(L1, tau_j1 * L1.z, effect = actuation))]
        #[appell(frame(L2 = L1.rotate_x(j2)), point(L2_origin = L1_origin + l * L1.z))]
        #[appell(torque(L2, tau_j2 * L2.x, effect = actuation), torque(L1, -(tau_j2 * L2.x), effect = actuation))]
        #[appell(frame(L3 = L2), point(L3_origin = L2_origin + c * L2.y + j3 * L3.z), point(j3_at = L2_origin + c * L2.y))]
        #[appell(force(L3_origin, tau_j3 * L3.z, effect = actuation), force(j3_at, -(tau_j3 * L3.z), effect = actuation))]
        #[appell(body(b2, center = L2_origin, frame = L2, mass = m, inertia = principal(i1, i2, i3)))]
        #[appell(body(b3, center = L3_origin, frame = L3, mass = m, inertia = principal(i1, i2, i3)))]
        {STRUCT}"#
        ),
    );
}

#[test]
fn a_locked_joint_is_a_dependent_joint_and_a_rate_constraint_of_its_effect() {
    let scenes = "#[appell(scene(loose, effects(gravity), speeds(j1, j2, s)))]
        #[appell(scene(braked, effects(gravity, brake), speeds(j1, s)))]";
    same_expansion(
        &format!(
            r#"
        #[appell(joint(j1, revolute(z), parent = N, child = L1))]
        #[appell(joint(j2, revolute(y), parent = L1, child = L2, xyz = [0, 0, l], lock = brake))]
        #[appell(joint(s, prismatic(z), parent = L2, child = L3, lock = clutch))]
        #[appell(body(b2, center = L2_origin + c * L2.x, frame = L2, mass = m, inertia = principal(i1, i2, i3)))]
        #[appell(body(b3, center = L3_origin + c * L3.x, frame = L3, mass = m, inertia = principal(i1, i2, i3)))]
        #[appell(gravity(-g * N.z))]
        {scenes}
        {STRUCT}"#
        ),
        &format!(
            r#"
        #[appell(joint(j1, revolute(z), parent = N, child = L1))]
        #[appell(joint(j2, revolute(y), parent = L1, child = L2, xyz = [0, 0, l], dependent))]
        #[appell(joint(s, prismatic(z), parent = L2, child = L3, dependent))]
        #[appell(body(b2, center = L2_origin + c * L2.x, frame = L2, mass = m, inertia = principal(i1, i2, i3)))]
        #[appell(body(b3, center = L3_origin + c * L3.x, frame = L3, mass = m, inertia = principal(i1, i2, i3)))]
        #[appell(gravity(-g * N.z))]
        #[appell(nonholonomic(dt(j2) == 0, effect = brake), nonholonomic(dt(s) == 0, effect = clutch))]
        {scenes}
        {STRUCT}"#
        ),
    );
}

fn four_bar(marks: [&str; 3]) -> String {
    let [m1, m2, m3] = marks;
    expand_str(&format!(
        r#"
        #[appell(joint(j1, revolute(z), parent = N, child = A{m1}))]
        #[appell(joint(j2, revolute(z), parent = A, child = B, xyz = [l, 0, 0]{m2}))]
        #[appell(joint(j3, revolute(z), parent = N, child = C, xyz = [c, 0, 0]{m3}))]
        #[appell(point(B_end = B_origin + l * B.x), point(C_end = C_origin + l * C.x))]
        #[appell(holonomic(B_end == C_end))]
        #[appell(body(a, center = A_origin, frame = A, mass = m, inertia = principal(i1, i2, i3)))]
        #[appell(body(b, center = B_origin, frame = B, mass = m, inertia = principal(i1, i2, i3)))]
        #[appell(body(cc, center = C_origin, frame = C, mass = m, inertia = principal(i1, i2, i3)))]
        {STRUCT}"#
    ))
}

#[test]
fn a_loop_of_joints_marks_the_joints_it_makes_dependent() {
    // Three joints, two loop-closure rows: one privileged speed.
    let out = four_bar(["", ", dependent", ", dependent"]);
    assert!(!out.contains("compile_error"), "{out}");
    assert!(
        out.contains(r#"speeds : & ["j1_dot"]"#) || out.contains(r#"speeds : & ["j1"]"#),
        "{out}"
    );
    assert!(out.contains(r#"dependent : & ["j2" , "j3"]"#), "{out}");
    let out = four_bar(["", "", ", dependent"]);
    assert!(
        out.contains("2 privileged speed(s) with 2 velocity constraint(s)"),
        "{out}"
    );
}

fn error_of(items: &str) -> String {
    let out = expand_str(&format!("{items}\n{STRUCT}"));
    assert!(out.contains("compile_error"), "{out}");
    out
}

#[test]
fn bad_joints_say_what_to_write() {
    let e = error_of("#[appell(joint(j, hinge(z), parent = N, child = A))]");
    assert!(e.contains("unknown joint kind `hinge`"), "{e}");
    let e = error_of("#[appell(joint(j, revolute, parent = N, child = A))]");
    assert!(e.contains("needs its axis"), "{e}");
    let e = error_of("#[appell(joint(j, revolute(w), parent = N, child = A))]");
    assert!(e.contains("a joint axis is"), "{e}");
    let e = error_of("#[appell(joint(j, revolute(z), child = A))]");
    assert!(e.contains("needs `parent = A`"), "{e}");
    let e = error_of("#[appell(joint(j, revolute(z), parent = N, child = A, spring = 3))]");
    assert!(e.contains("unknown joint property `spring`"), "{e}");
    let e = error_of(
        "#[appell(frame(A = N.rotate_z(l)), joint(j, revolute(z), parent = A, child = B))]",
    );
    assert!(e.contains("has no origin"), "{e}");
    let e = error_of("#[appell(joint(j, planar([1, 0, 0]), parent = N, child = A))]");
    assert!(e.contains("a planar joint's normal"), "{e}");
    let e = error_of("#[appell(joint(j, spherical, parent = N, child = A, lock = brake))]");
    assert!(
        e.contains("`lock` is for revolute and prismatic joints"),
        "{e}"
    );
    let e = error_of("#[appell(joint(j, revolute(z), parent = N, child = A, lock = 2))]");
    assert!(e.contains("`lock` names the effect"), "{e}");
    let e = error_of("#[appell(joint(j, revolute(z), parent = N, child = A, lock = a, lock = b))]");
    assert!(e.contains("a joint takes one `lock`"), "{e}");
    let e = error_of("#[appell(joint(j, weld, parent = N, child = A, actuated))]");
    assert!(
        e.contains("`actuated` is for revolute and prismatic joints"),
        "{e}"
    );
}

#[test]
fn a_spherical_joint_is_a_quaternion_frame_with_angular_velocity_speeds() {
    same_expansion(
        &format!(
            r#"
        #[appell(joint(j, spherical, parent = N, child = B, xyz = [0, 0, l]))]
        #[appell(body(b, center = B_origin + c * B.z, frame = B, mass = m, inertia = principal(i1, i2, i3)))]
        #[appell(gravity(-g * N.z))]
        {STRUCT}"#
        ),
        &format!(
            r#"
        #[appell(coordinates(j_qw, j_qx, j_qy, j_qz))]
        #[appell(speeds(
            j_wx = 2 * (j_qw * dt(j_qx) - dt(j_qw) * j_qx - (j_qy * dt(j_qz) - j_qz * dt(j_qy))),
            j_wy = 2 * (j_qw * dt(j_qy) - dt(j_qw) * j_qy - (j_qz * dt(j_qx) - j_qx * dt(j_qz))),
            j_wz = 2 * (j_qw * dt(j_qz) - dt(j_qw) * j_qz - (j_qx * dt(j_qy) - j_qy * dt(j_qx)))))]
        #[appell(holonomic(j_qw * j_qw + j_qx * j_qx + j_qy * j_qy + j_qz * j_qz == 1))]
        #[appell(frame(B = N.quaternion(j_qw, j_qx, j_qy, j_qz)), point(B_origin = O + l * N.z))]
        #[appell(point(b_center = B_origin + c * B.z))]
        #[appell(body(b, center = b_center, frame = B, mass = m, inertia = principal(i1, i2, i3)))]
        #[appell(gravity(-g * N.z))]
        {STRUCT}"#
        ),
    );
}
