//! An oracle for discontinuity meshes that knows nothing of events. Along seeded lines across a
//! receiver, the exact direct light is sampled at a fine, even step; its third differences stand
//! out from their neighbours wherever the value, the slope or the curvature jumps. Every jump
//! found must have a discontinuity segment through it (within three steps, 6e-4 of the receiver,
//! plus the EEE chord tolerance), and every segment must have a jump across it (probed along a
//! short line at right angles to it). Events are found from every blocker, however little it can
//! hide (`event_tolerance` 0). Contact lines with darkness on both sides are the one exception:
//! they bound what the reflected light reaches, not a change of the direct light.

use glam::{DVec2, DVec3};
use penumbra_meshing::discontinuity::{
    DiscontinuityOptions, DiscontinuitySegment, Event, EventSet, find_discontinuities,
};
use penumbra_scenes::SplitMix64;
use penumbra_scenes::polygon::{clip_segment, closest_point_on_segment};
use penumbra_scenes::{PlaneFrame, Rgb, Scene, Surface, SurfaceId, Visibility, builtin};
use penumbra_solver::{DirectLight, ReceivingPoint};
use rayon::prelude::*;

/// The sampling step, as a fraction of the receiver's diameter.
const STEP: f64 = 2e-4;
/// A third difference is a jump when it exceeds this many times the typical one beside it.
const STANDS_OUT: f64 = 25.0;
/// Neighbours whose third differences give the typical one: from this many steps away...
const BESIDE_FROM: usize = 5;
/// ...to this many.
const BESIDE_TO: usize = 14;
/// Relative rounding error of one value of the exact light, which the differences amplify.
const VALUE_ROUNDING: f64 = 1e-13;

/// The light from one emitter over one receiver, and the receiver's flat frame.
struct Field<'a> {
    direct: &'a DirectLight<'a>,
    emitter: usize,
    receiver: SurfaceId,
    frame: PlaneFrame,
    outline: Vec<DVec2>,
    /// The sampling step, in the scene's units.
    h: f64,
}

impl Field<'_> {
    fn value(&self, p: DVec2) -> f64 {
        let x = ReceivingPoint::interior(self.frame.to_3d(p), self.frame.normal);
        self.direct
            .form_factor_visible(&x, self.receiver, self.emitter)
    }

    /// Values every `h` along `a -> b` (the last at or before `b`).
    fn samples(&self, a: DVec2, b: DVec2) -> Vec<f64> {
        let n = (a.distance(b) / self.h).floor() as usize + 1;
        let dir = (b - a).normalize();
        (0..n)
            .map(|i| self.value(a + dir * (i as f64 * self.h)))
            .collect()
    }
}

/// A jump found along a line: where (distance from the line's start), the stretch of windows
/// that stood out, and how far it stood out.
#[derive(Clone, Copy, Debug)]
struct Jump {
    at: f64,
    from: f64,
    to: f64,
    ratio: f64,
}

fn median(mut v: Vec<f64>) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    Some(v[v.len() / 2])
}

/// The jumps in value, slope or curvature of `f`, sampled every `h`.
fn jumps(f: &[f64], h: f64) -> Vec<Jump> {
    if f.len() < 4 {
        return Vec::new();
    }
    let scale = f.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let noise = 64.0 * VALUE_ROUNDING * scale;
    let d: Vec<f64> = f
        .windows(4)
        .map(|w| (w[3] - 3.0 * w[2] + 3.0 * w[1] - w[0]).abs())
        .collect();
    let typical = |i: usize| {
        let left = (i >= BESIDE_TO).then(|| median(d[i - BESIDE_TO..=i - BESIDE_FROM].to_vec()));
        let right =
            (i + BESIDE_TO < d.len()).then(|| median(d[i + BESIDE_FROM..=i + BESIDE_TO].to_vec()));
        match (left.flatten(), right.flatten()) {
            (Some(l), Some(r)) => l.min(r),
            (Some(x), None) | (None, Some(x)) => x,
            (None, None) => 0.0,
        }
    };
    let mut out: Vec<Jump> = Vec::new();
    let mut best = 0.0;
    for i in 0..d.len() {
        let bar = STANDS_OUT * typical(i) + noise;
        if d[i] <= bar {
            continue;
        }
        let ratio = d[i] / bar;
        let centre = (i as f64 + 1.5) * h;
        match out.last_mut() {
            Some(j) if i as f64 * h <= j.to + 2.0 * h => {
                j.to = (i + 3) as f64 * h;
                if d[i] > best {
                    best = d[i];
                    j.at = centre;
                    j.ratio = j.ratio.max(ratio);
                }
            }
            _ => {
                best = d[i];
                out.push(Jump {
                    at: centre,
                    from: i as f64 * h,
                    to: (i + 3) as f64 * h,
                    ratio,
                });
            }
        }
    }
    out
}

fn distance_to(p: DVec2, [a, b]: [DVec2; 2]) -> f64 {
    p.distance(closest_point_on_segment(p, a, b))
}

/// What the oracle found on one receiver.
#[derive(Debug, Default)]
struct Verdict {
    lines: usize,
    jumps: usize,
    /// Jumps with no segment through them: (point, ratio).
    unexplained: Vec<(DVec2, f64)>,
    segments_probed: usize,
    segments_crowded: usize,
    dark_contacts: usize,
    /// Segments with no jump across them.
    silent: Vec<(DiscontinuitySegment, f64, f64)>,
}

fn oracle(scene: &Scene, receiver: &str, events: EventSet, lines: usize, seed: u64) -> Verdict {
    let vis = Visibility::build(scene);
    let options = DiscontinuityOptions {
        events,
        event_tolerance: 0.0,
        ..DiscontinuityOptions::default()
    };
    let found = find_discontinuities(scene, &vis, &options);
    let r = scene.surface_id(receiver).expect("receiver");
    let polygon = &scene.surfaces[r].polygon;
    let frame = PlaneFrame::of_polygon(polygon).expect("flat receiver");
    let outline: Vec<DVec2> = polygon.iter().map(|&p| frame.to_2d(p)).collect();
    let h = STEP * penumbra_scenes::polygon::diameter(polygon);
    let direct = DirectLight::new(scene, &vis);
    let mut verdict = Verdict::default();
    for emitter in 0..direct.emitter_count() {
        let e = direct.emitter_surface(emitter);
        let field = Field {
            direct: &direct,
            emitter,
            receiver: r,
            frame,
            outline: outline.clone(),
            h,
        };
        let kept: Vec<DiscontinuitySegment> = found.segments[r]
            .iter()
            .filter(|s| s.emitter == e)
            .copied()
            .collect();
        let segments: Vec<[DVec2; 2]> = kept
            .iter()
            .map(|s| [frame.to_2d(s.from), frame.to_2d(s.to)])
            .collect();
        // Jumps are placed to within a few steps; EEE curves are polylines within their chord
        // tolerance (a 1e-4 of the receiver, `DiscontinuityOptions::eee_tolerance`).
        let tolerance =
            3.0 * h + options.eee_tolerance * penumbra_scenes::polygon::diameter(polygon);
        along_lines(
            &field,
            &segments,
            lines,
            seed ^ emitter as u64,
            tolerance,
            &mut verdict,
        );
        across_segments(&field, &kept, &segments, &mut verdict);
    }
    verdict
}

/// Every jump along `lines` seeded chords of the receiver has a segment within `tolerance`.
fn along_lines(
    field: &Field,
    segments: &[[DVec2; 2]],
    lines: usize,
    seed: u64,
    tolerance: f64,
    verdict: &mut Verdict,
) {
    let (lo, hi) = field.outline.iter().fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    let reach = lo.distance(hi);
    let chords: Vec<[DVec2; 2]> = {
        let mut rng = SplitMix64::new(seed);
        let mut out = Vec::new();
        while out.len() < lines {
            let c = lo + (hi - lo) * DVec2::new(rng.next_f64(), rng.next_f64());
            let turn = std::f64::consts::PI * rng.next_f64();
            let dir = DVec2::new(turn.cos(), turn.sin());
            let (a, b) = (c - dir * reach, c + dir * reach);
            for [s, t] in clip_segment(a, b, &field.outline) {
                let (p, q) = (a.lerp(b, s), a.lerp(b, t));
                // Away from the receiver's own edges, where the light is not defined beyond.
                let inset = 4.0 * field.h;
                if p.distance(q) > 40.0 * field.h {
                    let d = (q - p).normalize();
                    out.push([p + d * inset, q - d * inset]);
                }
            }
        }
        out.truncate(lines);
        out
    };
    let found: Vec<Vec<(DVec2, Jump)>> = chords
        .par_iter()
        .map(|&[a, b]| {
            let dir = (b - a).normalize();
            jumps(&field.samples(a, b), field.h)
                .into_iter()
                .map(|j| (a + dir * j.at, j))
                .collect()
        })
        .collect();
    verdict.lines += chords.len();
    for (chord, (p, j)) in found
        .into_iter()
        .enumerate()
        .flat_map(|(c, list)| list.into_iter().map(move |x| (c, x)))
    {
        verdict.jumps += 1;
        let slack = 0.5 * (j.to - j.from);
        let near = segments
            .iter()
            .any(|&s| distance_to(p, s) <= tolerance + slack);
        let [a, b] = chords[chord];
        if !near && stands_out_finer(field, p, (b - a).normalize(), j.ratio) {
            verdict.unexplained.push((p, j.ratio));
        }
    }
}

/// Whether a jump found at `p` along `dir` (standing `ratio` times over the bar) is one: sampled
/// four times finer, a jump of value, slope or curvature stands out 4 to 64 times more against
/// the smooth light's differences, which shrink as the cube of the step; a bump of a smooth
/// light only as much.
fn stands_out_finer(field: &Field, p: DVec2, dir: DVec2, ratio: f64) -> bool {
    let h = 0.25 * field.h;
    let half = 2.0 * (BESIDE_TO + 10) as f64 * h;
    let values: Vec<f64> = (0..=(2.0 * half / h).round() as usize)
        .map(|i| field.value(p + dir * (i as f64 * h - half)))
        .collect();
    jumps(&values, h)
        .iter()
        .any(|j| (j.from - 8.0 * h..=j.to + 8.0 * h).contains(&half) && j.ratio >= 2.0 * ratio)
}

/// Every segment has a jump across it, probed at right angles to it at a point no other segment
/// comes near.
fn across_segments(
    field: &Field,
    kept: &[DiscontinuitySegment],
    segments: &[[DVec2; 2]],
    verdict: &mut Verdict,
) {
    let h = field.h;
    let half = (BESIDE_TO + 10) as f64 * h;
    for (k, &[a, b]) in segments.iter().enumerate() {
        let dir = (b - a).normalize();
        let across = dir.perp();
        let collinear = |s: [DVec2; 2]| {
            s.iter()
                .all(|&p| (p - a).perp_dot(dir).abs() <= 1e-9 * half.max(1.0))
        };
        // A piece that carries the line on from one of its ends (the chords of an EEE curve):
        // a probe across this one does not cross it.
        let touches = |p: DVec2, s: [DVec2; 2]| s.iter().any(|&q| q.distance(p) <= 1e-9 * half);
        let carries_on = |s: [DVec2; 2]| {
            (touches(a, s) || touches(b, s)) && (s[1] - s[0]).normalize().dot(dir).abs() > 0.7
        };
        let free_ends: Vec<DVec2> = [a, b]
            .into_iter()
            .filter(|&p| {
                !segments
                    .iter()
                    .enumerate()
                    .any(|(o, &s)| o != k && touches(p, s) && carries_on(s))
            })
            .collect();
        let spot = [0.5, 0.3, 0.7, 0.15, 0.85, 0.4, 0.6, 0.2, 0.8, 0.1, 0.9]
            .into_iter()
            .map(|u| a.lerp(b, u))
            .find(|&m| {
                free_ends.iter().all(|&p| m.distance(p) > half)
                    && segments.iter().enumerate().all(|(o, &s)| {
                        o == k || collinear(s) || carries_on(s) || distance_to(m, s) > half
                    })
            });
        let Some(m) = spot else {
            verdict.segments_crowded += 1;
            continue;
        };
        verdict.segments_probed += 1;
        let values = field.samples(m - across * half, m + across * half);
        let found = jumps(&values, h);
        let hit = found
            .iter()
            .any(|j| (j.from - 2.0 * h..=j.to + 2.0 * h).contains(&half));
        // A contact line with darkness on both sides bounds what the reflected light reaches
        // (the floor under a block sees none of the room), not a change of the direct light.
        let dark = values.iter().all(|&v| v == 0.0);
        if dark && kept[k].event == Event::Contact {
            verdict.dark_contacts += 1;
        } else if !hit {
            verdict
                .silent
                .push((kept[k], values[0], values[values.len() - 1]));
        }
    }
}

/// A regular `n`-gon of circumradius `radius`, turned by `turn` in its plane, then tilted by
/// `tilt` about the x axis and moved to `centre`; facing down before the tilt when `down`.
fn regular(n: usize, radius: f64, turn: f64, tilt: f64, centre: DVec3, down: bool) -> Vec<DVec3> {
    let rot = glam::DQuat::from_rotation_x(tilt);
    let mut p: Vec<DVec3> = (0..n)
        .map(|i| {
            let a = turn + std::f64::consts::TAU * i as f64 / n as f64;
            centre + rot * DVec3::new(radius * a.cos(), radius * a.sin(), 0.0)
        })
        .collect();
    if down {
        p.reverse();
    }
    p
}

fn floor(half: f64) -> Surface {
    grey(
        "floor",
        vec![
            DVec3::new(-half, -half, 0.0),
            DVec3::new(half, -half, 0.0),
            DVec3::new(half, half, 0.0),
            DVec3::new(-half, half, 0.0),
        ],
    )
}

/// A surface of reflectance 0.5 that does not emit.
fn grey(name: impl Into<String>, polygon: Vec<DVec3>) -> Surface {
    Surface::new(name, polygon, Rgb::splat(0.5))
}

fn light(polygon: Vec<DVec3>) -> Surface {
    Surface::new("light", polygon, Rgb::ZERO).with_emission(Rgb::splat(1.0))
}

fn report(name: &str, v: &Verdict) -> String {
    format!(
        "{name}: {} lines, {} jumps, {} unexplained {:?}; {} segments probed ({} crowded), {} silent {:?}",
        v.lines,
        v.jumps,
        v.unexplained.len(),
        &v.unexplained[..v.unexplained.len().min(6)],
        v.segments_probed,
        v.segments_crowded,
        v.silent.len(),
        &v.silent[..v.silent.len().min(6)]
    )
}

/// The faces of a convex solid with corners `corners`, each face (a list of corner indices)
/// turned to face outward.
fn solid(name: &str, corners: &[DVec3], faces: &[&[usize]]) -> Vec<Surface> {
    let centre = corners.iter().sum::<DVec3>() / corners.len() as f64;
    faces
        .iter()
        .enumerate()
        .map(|(i, f)| {
            let mut p: Vec<DVec3> = f.iter().map(|&k| corners[k]).collect();
            let n = penumbra_scenes::polygon::newell_normal(&p);
            if n.dot(p[0] - centre) < 0.0 {
                p.reverse();
            }
            grey(format!("{name}{i}"), p)
        })
        .collect()
}

/// A box of half sizes `half`, turned by `turn` and placed at `centre`.
fn cuboid(name: &str, half: DVec3, turn: glam::DQuat, centre: DVec3) -> Vec<Surface> {
    let corners: Vec<DVec3> = (0..8)
        .map(|i| {
            let s = DVec3::new(
                if i & 1 == 0 { -1.0 } else { 1.0 },
                if i & 2 == 0 { -1.0 } else { 1.0 },
                if i & 4 == 0 { -1.0 } else { 1.0 },
            );
            centre + turn * (s * half)
        })
        .collect();
    let faces: [&[usize]; 6] = [
        &[0, 1, 3, 2],
        &[4, 5, 7, 6],
        &[0, 1, 5, 4],
        &[2, 3, 7, 6],
        &[0, 2, 6, 4],
        &[1, 3, 7, 5],
    ];
    solid(name, &corners, &faces)
}

fn scene_of(name: &str, surfaces: Vec<Surface>) -> Scene {
    Scene {
        up: None,
        unit: None,
        name: name.into(),
        camera: None,
        surfaces,
    }
}

/// Asserts what the oracle found: no jump without a segment, no segment without a jump, and
/// enough of both to mean something.
fn assert_complete(scene: &Scene, receiver: &str, lines: usize) {
    // Two sets of lines: a short run of an event between two others shows on some lines only.
    for seed in [7, 1] {
        let v = oracle(scene, receiver, EventSet::Complete, lines, seed);
        let line = report(
            &format!("{} {receiver}, lines seeded {seed}", scene.name),
            &v,
        );
        eprintln!("{line}");
        assert!(v.unexplained.is_empty() && v.silent.is_empty(), "{line}");
        assert!(
            v.jumps >= lines && v.segments_probed >= 8 && v.segments_probed >= v.segments_crowded,
            "{line}"
        );
    }
}

#[test]
fn boxes_tetrahedra_and_overlapping_blockers() {
    let tilt = glam::DQuat::from_euler(glam::EulerRot::XYZ, 0.3, -0.5, 0.8);
    let hovering = [
        vec![light(regular(
            4,
            0.6,
            0.2,
            0.0,
            DVec3::new(0.0, 0.0, 3.0),
            true,
        ))],
        cuboid(
            "box",
            DVec3::new(0.4, 0.3, 0.2),
            tilt,
            DVec3::new(0.1, 0.0, 1.3),
        ),
        vec![floor(2.5)],
    ]
    .concat();
    let standing = [
        vec![light(regular(
            5,
            0.5,
            0.4,
            0.2,
            DVec3::new(-0.3, 0.2, 3.0),
            true,
        ))],
        cuboid(
            "box",
            DVec3::new(0.4, 0.3, 0.5),
            glam::DQuat::from_rotation_z(0.7),
            DVec3::new(0.2, 0.0, 0.5),
        ),
        vec![floor(2.5)],
    ]
    .concat();
    let tetra = [
        vec![light(regular(
            3,
            0.7,
            0.9,
            -0.25,
            DVec3::new(0.2, -0.1, 3.2),
            true,
        ))],
        solid(
            "tetra",
            &[
                DVec3::new(-0.5, -0.3, 1.0),
                DVec3::new(0.6, -0.2, 1.2),
                DVec3::new(0.1, 0.55, 0.9),
                DVec3::new(0.05, 0.0, 1.75),
            ],
            &[&[0, 1, 2], &[0, 1, 3], &[1, 2, 3], &[0, 2, 3]],
        ),
        vec![floor(2.5)],
    ]
    .concat();
    let overlapping = [
        vec![light(regular(
            4,
            0.6,
            0.0,
            0.0,
            DVec3::new(0.0, 0.0, 3.0),
            true,
        ))],
        vec![
            grey(
                "low",
                regular(4, 0.45, 0.3, 0.15, DVec3::new(-0.15, 0.0, 1.0), true),
            ),
            grey(
                "high",
                regular(5, 0.4, 1.1, -0.2, DVec3::new(0.2, 0.1, 1.6), true),
            ),
        ],
        vec![floor(2.5)],
    ]
    .concat();
    for (name, surfaces) in [
        ("hovering box", hovering),
        ("standing box", standing),
        ("tetrahedron", tetra),
        ("overlapping faces", overlapping),
    ] {
        assert_complete(&scene_of(name, surfaces), "floor", 60);
    }
}

/// Scenes rich in EEE events (skew edges of different blockers one above the other). Each of the
/// EEE search's culling rules (silhouette from the emitter edge, the shadow reaching the receiver,
/// the second edge inside the first one's shadow region, each edge crossing the other's sweep,
/// grazing, trimming) would show here as a jump without its segment if it dropped a real event.
#[test]
fn eee_rich_scenes() {
    assert_complete(&builtin::crossed_bars(), "floor", 60);
    let skew = [
        vec![light(regular(
            3,
            0.7,
            0.3,
            0.1,
            DVec3::new(0.1, 0.0, 3.0),
            true,
        ))],
        cuboid(
            "upper",
            DVec3::new(0.7, 0.06, 0.05),
            glam::DQuat::from_euler(glam::EulerRot::XYZ, 0.2, 0.1, 0.5),
            DVec3::new(0.0, 0.1, 1.7),
        ),
        cuboid(
            "lower",
            DVec3::new(0.08, 0.8, 0.06),
            glam::DQuat::from_euler(glam::EulerRot::XYZ, -0.15, 0.25, 0.3),
            DVec3::new(0.1, -0.05, 1.0),
        ),
        vec![floor(2.5)],
    ]
    .concat();
    assert_complete(&scene_of("skew boxes", skew), "floor", 60);
}

/// Any convex light over any convex blocker, in parallel planes and tilted: every jump has its
/// segment with complete events. With extremal ones the inner lines are missing, and the oracle
/// finds their jumps: it can fail.
#[test]
fn single_faces_parallel_and_tilted() {
    let mut rng = SplitMix64::new(14);
    for case in 0..8 {
        let n = 3 + (rng.next_u64() % 4) as usize;
        let k = 3 + (rng.next_u64() % 4) as usize;
        let parallel = case < 3;
        let mut tilt = || {
            if parallel {
                0.0
            } else {
                0.6 * (rng.next_f64() - 0.5)
            }
        };
        let (lt, bt) = (tilt(), tilt());
        let centre = DVec3::new(
            0.3 * (rng.next_f64() - 0.5),
            0.3 * (rng.next_f64() - 0.5),
            1.2,
        );
        let scene = scene_of(
            &format!("{n}-gon over {k}-gon, case {case}"),
            vec![
                light(regular(
                    n,
                    0.6,
                    rng.next_f64(),
                    lt,
                    DVec3::new(0.0, 0.0, 3.0),
                    true,
                )),
                grey(
                    "blocker",
                    regular(k, 0.45, 3.0 * rng.next_f64(), bt, centre, true),
                ),
                floor(2.5),
            ],
        );
        assert_complete(&scene, "floor", 40);
        let extremal = oracle(&scene, "floor", EventSet::Extremal, 40, 7);
        assert!(
            extremal.unexplained.len() >= 4,
            "{}",
            report(&format!("{} extremal", scene.name), &extremal)
        );
    }
}

/// The Cornell box, EEE on: its floor, and the back wall the blocks shade.
#[test]
fn cornell_box() {
    let scene = builtin::cornell();
    assert_complete(&scene, "floor", 40);
    assert_complete(&scene, "back_wall", 30);
}

/// A tilted light whose own plane cuts a wall: above the cut the wall gets no light, below it the
/// light is seen at a growing angle, and the slope jumps along the cut (a horizon line, order 1).
#[test]
fn a_wall_cut_by_the_lights_own_plane() {
    let mut wall = vec![
        DVec3::new(-2.0, 1.5, 0.0),
        DVec3::new(2.0, 1.5, 0.0),
        DVec3::new(2.0, 1.5, 3.0),
        DVec3::new(-2.0, 1.5, 3.0),
    ];
    // Facing the light, towards -y.
    if penumbra_scenes::polygon::newell_normal(&wall).y > 0.0 {
        wall.reverse();
    }
    let scene = scene_of(
        "tilted light and a wall",
        vec![
            light(regular(4, 0.5, 0.3, -0.5, DVec3::new(0.0, 0.0, 2.0), true)),
            grey(
                "blocker",
                regular(3, 0.3, 0.2, 0.0, DVec3::new(0.1, 0.4, 1.2), true),
            ),
            grey("wall", wall),
            floor(2.5),
        ],
    );
    let vis = Visibility::build(&scene);
    let found = find_discontinuities(&scene, &vis, &DiscontinuityOptions::default());
    let wall = scene.surface_id("wall").expect("wall");
    let horizons: Vec<_> = found.segments[wall]
        .iter()
        .filter(|s| s.event == Event::Horizon)
        .collect();
    assert_eq!(horizons.len(), 1, "{:?}", found.stats);
    assert_eq!(horizons[0].order, 1);
    assert_complete(&scene, "wall", 40);
}
