//! Jacobi gathering with push–pull (Hanrahan, Salzman & Aupperle 1991): every node gathers
//! along its links from the radiosities of the last sweep; then the gathered light is pushed down
//! the hierarchy (an element passes its irradiance to its children, a cluster its light per axis
//! direction, read by each surface for its own normal), the leaves reflect it on top of the
//! direct light they reflect, and radiosities are pulled up again as area means (powers per
//! axis direction for clusters).

use penumbra_scenes::Rgb;
use rayon::prelude::*;

use super::links::{Link, Radiosities, Transfer};
use super::transfer::{Axes, axis_weights, irradiance_from_axes, power_shares};
use super::tree::{Hierarchy, NONE};

/// The light in the hierarchy: radiosities and irradiances of elements, powers of clusters.
#[derive(Clone, Debug)]
pub(crate) struct Field {
    /// Per node: an element's mean reflected radiosity (zero for clusters).
    pub b: Vec<Rgb>,
    /// Per cluster slot: power per axis direction.
    pub q: Vec<Axes>,
    /// Per node: an element's mean irradiance from reflected light, its ancestors' included.
    pub irradiance: Vec<Rgb>,
    /// Per node: the least and greatest radiosity of its leaves.
    low: Vec<Rgb>,
    high: Vec<Rgb>,
}

impl Field {
    fn new(nodes: usize, clusters: usize) -> Field {
        Field {
            b: vec![Rgb::ZERO; nodes],
            q: vec![[Rgb::ZERO; 6]; clusters],
            irradiance: vec![Rgb::ZERO; nodes],
            low: vec![Rgb::ZERO; nodes],
            high: vec![Rgb::ZERO; nodes],
        }
    }
}

/// The hierarchy with its links grouped by receiver, and what each element reflects of the
/// direct light.
pub(crate) struct System<'a> {
    pub hierarchy: &'a Hierarchy,
    /// Each node's slot among the clusters (`NONE` for elements).
    pub slot: Vec<u32>,
    pub clusters: usize,
    /// Per node: the mean radiosity it reflects of the exact direct light.
    pub direct: Vec<Rgb>,
    /// Links sorted by receiver, and for each node the range of its own.
    pub links: Vec<Link>,
    pub first_link: Vec<u32>,
}

impl<'a> System<'a> {
    /// `leaf_direct` is each leaf's reflected direct radiosity (by node; anything elsewhere).
    pub(super) fn new(hierarchy: &'a Hierarchy, leaf_direct: Vec<Rgb>) -> System<'a> {
        let mut slot = vec![NONE; hierarchy.nodes.len()];
        let mut clusters = 0;
        for (i, n) in hierarchy.nodes.iter().enumerate() {
            if n.is_cluster() {
                slot[i] = clusters;
                clusters += 1;
            }
        }
        let mut system = System {
            hierarchy,
            slot,
            clusters: clusters as usize,
            direct: leaf_direct,
            links: Vec::new(),
            first_link: vec![0; hierarchy.nodes.len() + 1],
        };
        if let Some(root) = hierarchy.root {
            system.pull_direct(root);
        }
        system
    }

    /// Means of the leaves' direct light up the element trees.
    fn pull_direct(&mut self, id: u32) -> Rgb {
        let node = self.hierarchy.node(id);
        if let Some(children) = node.children {
            let sum: Rgb = children
                .iter()
                .map(|&c| self.pull_direct(c) * self.hierarchy.node(c).area)
                .sum();
            self.direct[id as usize] = sum / node.area;
        }
        self.direct[id as usize]
    }

    /// Replaces the links (in any order; sorted here by receiver, stably).
    pub(super) fn set_links(&mut self, mut links: Vec<Link>) {
        links.sort_by_key(|l| l.receiver);
        self.first_link.iter_mut().for_each(|f| *f = 0);
        for l in &links {
            self.first_link[l.receiver as usize + 1] += 1;
        }
        for i in 1..self.first_link.len() {
            self.first_link[i] += self.first_link[i - 1];
        }
        self.links = links;
    }

    /// The links `id` receives along.
    pub(super) fn links_of(&self, id: u32) -> &[Link] {
        let (a, b) = (
            self.first_link[id as usize] as usize,
            self.first_link[id as usize + 1] as usize,
        );
        &self.links[a..b]
    }

    pub(super) fn radiosities<'f>(&'f self, field: &'f Field) -> Radiosities<'f> {
        Radiosities {
            b: &field.b,
            q: &field.q,
            low: &field.low,
            high: &field.high,
            slot: &self.slot,
        }
    }

    /// The field before any reflected light has been gathered: the direct light reflected.
    pub(super) fn initial_field(&self) -> Field {
        let n = self.hierarchy.nodes.len();
        let mut field = Field::new(n, self.clusters);
        if let Some(root) = self.hierarchy.root {
            let gathered = Gathered {
                h: vec![Rgb::ZERO; n],
                g: vec![[Rgb::ZERO; 6]; self.clusters],
            };
            self.push_pull(root, Down::Axes([Rgb::ZERO; 6]), &gathered, &mut field);
        }
        field
    }

    /// One Jacobi sweep from `field`: the new field.
    pub(super) fn sweep(&self, field: &Field) -> Field {
        let gathered = self.gather(field);
        let mut next = Field::new(field.b.len(), self.clusters);
        if let Some(root) = self.hierarchy.root {
            self.push_pull(root, Down::Axes([Rgb::ZERO; 6]), &gathered, &mut next);
        }
        next
    }

    /// What every node gathers along its own links.
    fn gather(&self, field: &Field) -> Gathered {
        let h = self.hierarchy;
        let state = self.radiosities(field);
        let receivers: Vec<u32> = (0..h.nodes.len() as u32)
            .filter(|&i| self.first_link[i as usize] != self.first_link[i as usize + 1])
            .collect();
        let values: Vec<Axes> = receivers
            .par_iter()
            .map(|&r| {
                let rn = h.node(r);
                let mut sum = [Rgb::ZERO; 6];
                for link in self.links_of(r) {
                    let sn = h.node(link.source);
                    match link.transfer {
                        Transfer::Factor { factor, .. } => {
                            sum[0] += field.b[link.source as usize] * factor;
                        }
                        Transfer::Far {
                            direction,
                            distance2,
                            visible,
                        } => {
                            let i =
                                state.intensity(sn, link.source, direction) * (visible / distance2);
                            if rn.is_cluster() {
                                for (s, w) in sum.iter_mut().zip(axis_weights(-direction)) {
                                    *s += i * w;
                                }
                            } else {
                                sum[0] += i * rn.normal.dot(-direction).max(0.0);
                            }
                        }
                    }
                }
                sum
            })
            .collect();
        let mut gathered = Gathered {
            h: vec![Rgb::ZERO; h.nodes.len()],
            g: vec![[Rgb::ZERO; 6]; self.clusters],
        };
        for (&r, v) in receivers.iter().zip(values) {
            match self.slot[r as usize] {
                NONE => gathered.h[r as usize] = v[0],
                s => gathered.g[s as usize] = v,
            }
        }
        gathered
    }

    /// Pushes `down` and what `id` gathered to its leaves, which reflect it, and pulls the
    /// radiosities (or powers) back up into `out`.
    fn push_pull(&self, id: u32, down: Down, gathered: &Gathered, out: &mut Field) {
        let node = self.hierarchy.node(id);
        match self.slot[id as usize] {
            NONE => {
                let down = match down {
                    Down::Irradiance(h) => h,
                    Down::Axes(g) => irradiance_from_axes(&g, node.normal),
                };
                let total = down + gathered.h[id as usize];
                out.irradiance[id as usize] = total;
                let i = id as usize;
                match node.children {
                    None => {
                        let b = self.direct[i] + node.reflectance.mul_rgb(total);
                        (out.b[i], out.low[i], out.high[i]) = (b, b, b);
                    }
                    Some(children) => {
                        let mut sum = Rgb::ZERO;
                        let (mut low, mut high) = (Rgb::splat(f64::INFINITY), Rgb::ZERO);
                        for c in children {
                            self.push_pull(c, Down::Irradiance(total), gathered, out);
                            let c = c as usize;
                            sum += out.b[c] * self.hierarchy.nodes[c].area;
                            low = Rgb::new(
                                low.r.min(out.low[c].r),
                                low.g.min(out.low[c].g),
                                low.b.min(out.low[c].b),
                            );
                            high = Rgb::new(
                                high.r.max(out.high[c].r),
                                high.g.max(out.high[c].g),
                                high.b.max(out.high[c].b),
                            );
                        }
                        (out.b[i], out.low[i], out.high[i]) = (sum / node.area, low, high);
                    }
                }
            }
            slot => {
                let mut total = match down {
                    Down::Axes(g) => g,
                    Down::Irradiance(_) => [Rgb::ZERO; 6],
                };
                for (t, g) in total.iter_mut().zip(&gathered.g[slot as usize]) {
                    *t += *g;
                }
                let mut power = [Rgb::ZERO; 6];
                for c in node.children.into_iter().flatten() {
                    let child = self.hierarchy.node(c);
                    match self.slot[c as usize] {
                        NONE => {
                            let h = irradiance_from_axes(&total, child.normal);
                            self.push_pull(c, Down::Irradiance(h), gathered, out);
                            let sent = out.b[c as usize] * child.area;
                            for (p, share) in power.iter_mut().zip(power_shares(child.normal)) {
                                *p += sent * share;
                            }
                        }
                        s => {
                            self.push_pull(c, Down::Axes(total), gathered, out);
                            for (p, q) in power.iter_mut().zip(&out.q[s as usize]) {
                                *p += *q;
                            }
                        }
                    }
                }
                out.q[slot as usize] = power;
            }
        }
    }

    /// Σ area × |change of radiosity| over the leaves, relative to Σ area × reflected direct
    /// radiosity (channel means): the sweep's relative residual.
    pub(super) fn change(&self, before: &Field, after: &Field) -> (f64, Rgb) {
        let (mut change, mut scale, mut signed) = (0.0, 0.0, Rgb::ZERO);
        for (i, n) in self.hierarchy.nodes.iter().enumerate() {
            if n.is_leaf() {
                let d = after.b[i] - before.b[i];
                change += d.map(f64::abs).mean() * n.area;
                signed += d * n.area;
                scale += self.direct[i].mean() * n.area;
            }
        }
        let relative = if scale > 0.0 { change / scale } else { change };
        (relative, signed)
    }
}

/// What comes down to a node from above.
#[derive(Clone, Copy)]
enum Down {
    Irradiance(Rgb),
    Axes(Axes),
}

/// What each node gathered along its own links.
struct Gathered {
    h: Vec<Rgb>,
    g: Vec<Axes>,
}
