//! Jacobi gathering with push–pull (Hanrahan, Salzman & Aupperle 1991): every node gathers
//! along its links from the radiosities of the last sweep; then the gathered light is pushed down
//! the hierarchy (an element passes its irradiance to its children, a cluster its light per axis
//! direction, read by each surface for its own normal), the leaves reflect it on top of the
//! direct light they reflect, and radiosities are pulled up again as area means (for clusters,
//! their power, and the large ones' intensities over directions).
//!
//! Each leaf's gathered light is scaled so that its form factors sum to its true total (see
//! [`super::totals`]): every row of the system then sums to ρ T ≤ ρ < 1, so the sweeps are a
//! contraction at any reflectance below one. The sweeps slow down as ρ nears one, along the
//! field's near-uniform part; after each sweep the residual's area mean is removed along the
//! uniform field (a one-unknown coarse correction, like Cohen et al.'s ambient term but exact
//! for that unknown), which leaves only the faster parts.

use penumbra_scenes::Rgb;
use rayon::prelude::*;

use super::directions::{self, Table};
use super::links::EXACT_CLUSTER_SURFACES;
use super::links::{Link, Radiosities, Transfer};
use super::transfer::{Axes, axis_weights, irradiance_from_axes};
use super::tree::{Hierarchy, NONE};

/// The light in the hierarchy: radiosities and irradiances of elements, powers of clusters.
#[derive(Clone, Debug)]
pub(crate) struct Field {
    /// Per node: an element's mean reflected radiosity (zero for clusters).
    pub b: Vec<Rgb>,
    /// Per cluster slot: the power it sends (W).
    pub power: Vec<Rgb>,
    /// Per table slot (clusters of more than [`EXACT_CLUSTER_SURFACES`] surfaces): intensity
    /// per sample direction.
    pub tables: Vec<Table>,
    /// Per node: an element's mean irradiance from reflected light, its ancestors' included.
    pub irradiance: Vec<Rgb>,
    /// Per node: the least and greatest radiosity of its leaves.
    low: Vec<Rgb>,
    high: Vec<Rgb>,
    /// Per element: the mean radiosity it gathers, its irradiance over the sum of its form
    /// factors (zero before any light is gathered).
    incoming: Vec<Rgb>,
}

impl Field {
    /// This field plus `gamma` times `other` (per channel), with `extra` times `gamma` more
    /// irradiance on each node: the sum of two solutions of the same links.
    pub(super) fn add_scaled(&mut self, other: &Field, gamma: Rgb, extra: &[f64]) {
        let add = |mine: &mut [Rgb], theirs: &[Rgb]| {
            for (m, t) in mine.iter_mut().zip(theirs) {
                *m += t.mul_rgb(gamma);
            }
        };
        add(&mut self.b, &other.b);
        add(&mut self.low, &other.low);
        add(&mut self.high, &other.high);
        add(&mut self.incoming, &other.incoming);
        add(&mut self.irradiance, &other.irradiance);
        for (h, &x) in self.irradiance.iter_mut().zip(extra) {
            *h += gamma * x;
        }
        add(&mut self.power, &other.power);
        for (mine, theirs) in self.tables.iter_mut().zip(&other.tables) {
            for (a, b) in mine.iter_mut().zip(theirs) {
                *a += b.mul_rgb(gamma);
            }
        }
    }

    fn new(nodes: usize, clusters: usize, tables: usize) -> Field {
        Field {
            b: vec![Rgb::ZERO; nodes],
            power: vec![Rgb::ZERO; clusters],
            tables: vec![directions::DARK; tables],
            irradiance: vec![Rgb::ZERO; nodes],
            low: vec![Rgb::ZERO; nodes],
            high: vec![Rgb::ZERO; nodes],
            incoming: vec![Rgb::ZERO; nodes],
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
    /// Each node's slot among the clusters with a table of intensities (`NONE` for others).
    pub table_slot: Vec<u32>,
    pub tables: usize,
    /// Per node: the mean radiosity it reflects of the exact direct light.
    pub direct: Vec<Rgb>,
    /// Links sorted by receiver, and for each node the range of its own.
    pub links: Vec<Link>,
    pub first_link: Vec<u32>,
    /// Per node: what a leaf's gathered light is multiplied by, its true total over the sum of
    /// its form factors (one elsewhere, and until totals are set).
    pub scale: Vec<f64>,
    /// Per node: a leaf's true total of form factors (what its links sum to after scaling).
    pub totals: Vec<f64>,
    /// Per node: the part of a leaf's total that surfaces which reflect cover.
    pub reflecting: Vec<f64>,
    /// Per node: the sum of the form factors along its links and its ancestors', unscaled
    /// (empty before the links are set).
    sums: Vec<f64>,
    /// Per node: whether a leaf's links changed since its total was found.
    stale: Vec<bool>,
    /// Per node: whether a leaf lies inside a closed solid (its total is then one).
    pub enclosed: Vec<bool>,
    /// Distance under which a point counts as lying on a plane.
    pub tol: f64,
    /// The field of unit radiosity on every element: what the links carry per unit.
    pub unit: Field,
    /// The field of unit radiosity on every element that reflects, zero on the others.
    pub unit_reflecting: Field,
}

impl<'a> System<'a> {
    /// `leaf_direct` is each leaf's reflected direct radiosity and `enclosed` whether it lies
    /// inside a closed solid (both by node; anything elsewhere); `tol` the distance under which
    /// a point counts as lying on a plane.
    pub(super) fn new(
        hierarchy: &'a Hierarchy,
        leaf_direct: Vec<Rgb>,
        enclosed: Vec<bool>,
        tol: f64,
    ) -> System<'a> {
        let mut slot = vec![NONE; hierarchy.nodes.len()];
        let mut clusters = 0;
        for (i, n) in hierarchy.nodes.iter().enumerate() {
            if n.is_cluster() {
                slot[i] = clusters;
                clusters += 1;
            }
        }
        let mut table_slot = vec![NONE; hierarchy.nodes.len()];
        let mut tables = 0;
        for (i, n) in hierarchy.nodes.iter().enumerate() {
            if n.is_cluster() && n.surfaces > EXACT_CLUSTER_SURFACES {
                table_slot[i] = tables;
                tables += 1;
            }
        }
        let n = hierarchy.nodes.len();
        let mut system = System {
            hierarchy,
            slot,
            clusters: clusters as usize,
            table_slot,
            tables: tables as usize,
            direct: vec![Rgb::splat(1.0); n],
            links: Vec::new(),
            first_link: vec![0; n + 1],
            scale: vec![1.0; n],
            totals: Vec::new(),
            reflecting: Vec::new(),
            sums: Vec::new(),
            stale: vec![true; n],
            enclosed,
            tol,
            unit: Field::new(0, 0, 0),
            unit_reflecting: Field::new(0, 0, 0),
        };
        system.unit = system.initial_field();
        let lit = hierarchy
            .nodes
            .iter()
            .map(|node| Rgb::splat(if node.reflects() { 1.0 } else { 0.0 }))
            .collect();
        system.set_direct(lit);
        system.unit_reflecting = system.initial_field();
        system.set_direct(leaf_direct);
        system
    }

    /// Replaces what each leaf reflects of the light that comes from outside the links (by
    /// node; anything elsewhere), and returns the old.
    pub(super) fn set_direct(&mut self, leaf_direct: Vec<Rgb>) -> Vec<Rgb> {
        let old = std::mem::replace(&mut self.direct, leaf_direct);
        if let Some(root) = self.hierarchy.root {
            self.pull_direct(root);
        }
        old
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

    /// Each node's sum of form factors along its links and its ancestors': the irradiance it
    /// gathers, unscaled, when every element's radiosity is one.
    pub(super) fn row_sums(&self) -> Vec<f64> {
        let gathered = self.gather(&self.unit);
        let mut out = Field::new(self.hierarchy.nodes.len(), self.clusters, self.tables);
        if let Some(root) = self.hierarchy.root {
            self.push_pull(root, Down::Axes([Rgb::ZERO; 6]), &gathered, false, &mut out);
        }
        out.irradiance.iter().map(|h| h.mean()).collect()
    }

    /// Each leaf's gathered light scaled so that its form factors sum to its total
    /// ([`super::totals`]), for the links as they are.
    fn rescale(&mut self) {
        let sums = self.row_sums();
        for (i, n) in self.hierarchy.nodes.iter().enumerate() {
            self.scale[i] = if n.is_leaf() && !n.is_cluster() && sums[i] > 0.0 {
                self.totals[i] / sums[i]
            } else {
                1.0
            };
        }
        self.sums = sums;
    }

    /// Finds again the totals of the leaves whose links changed since theirs were found, and
    /// scales them; false if none had.
    pub(super) fn settle_totals(&mut self) -> bool {
        if !self.stale.iter().any(|&s| s) {
            return false;
        }
        (self.totals, self.reflecting) = self.leaf_totals(&self.stale);
        self.stale.fill(false);
        self.rescale();
        true
    }

    /// Replaces the links (in any order; sorted here by receiver, stably), and scales the
    /// leaves along them. `changed` lists the receivers whose links were replaced, when only
    /// theirs were: the leaves below them keep the totals they had until
    /// [`Self::settle_totals`]. A total is the share of a leaf's view that surfaces cover, so
    /// links refined from coarser ones change it little, while finding it costs as much as the
    /// links it is found along: it is found once, along the final links.
    pub(super) fn set_links(&mut self, mut links: Vec<Link>, changed: Option<&[u32]>) {
        links.sort_by_key(|l| l.receiver);
        self.first_link.iter_mut().for_each(|f| *f = 0);
        for l in &links {
            self.first_link[l.receiver as usize + 1] += 1;
        }
        for i in 1..self.first_link.len() {
            self.first_link[i] += self.first_link[i - 1];
        }
        self.links = links;
        match changed {
            // Until totals are found, a leaf's is its sum, at most one (one inside a closed
            // solid): the sweeps are a contraction all the same.
            None => {
                let sums = self.row_sums();
                self.totals = (sums.iter().zip(&self.enclosed))
                    .map(|(&sum, &enclosed)| bounded(sum, enclosed))
                    .collect();
                self.reflecting.clone_from(&self.totals);
                self.stale.fill(true);
            }
            Some(changed) => self.mark_stale(changed),
        }
        self.rescale();
    }

    /// Marks the leaves below each of `receivers`.
    fn mark_stale(&mut self, receivers: &[u32]) {
        let h = self.hierarchy;
        for &r in receivers {
            let n = h.node(r);
            for t in &h.triangles[n.first as usize..n.end as usize] {
                self.stale[h.leaf_of_element[t.element as usize] as usize] = true;
            }
        }
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
            power: &field.power,
            low: &field.low,
            high: &field.high,
            incoming: &field.incoming,
            slot: &self.slot,
            tables: &field.tables,
            table_slot: &self.table_slot,
            hierarchy: self.hierarchy,
        }
    }

    /// The field before any reflected light has been gathered: the direct light reflected.
    pub(super) fn initial_field(&self) -> Field {
        let n = self.hierarchy.nodes.len();
        let mut field = Field::new(n, self.clusters, self.tables);
        if let Some(root) = self.hierarchy.root {
            let gathered = Gathered {
                h: vec![Rgb::ZERO; n],
                g: vec![[Rgb::ZERO; 6]; self.clusters],
            };
            self.push_pull(
                root,
                Down::Axes([Rgb::ZERO; 6]),
                &gathered,
                true,
                &mut field,
            );
        }
        field
    }

    /// One Jacobi sweep from `field`: the new field.
    pub(super) fn sweep(&self, field: &Field) -> Field {
        let gathered = self.gather(field);
        let mut next = Field::new(field.b.len(), self.clusters, self.tables);
        if let Some(root) = self.hierarchy.root {
            self.push_pull(root, Down::Axes([Rgb::ZERO; 6]), &gathered, true, &mut next);
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

    /// Pushes `down` and what `id` gathered to its leaves, which reflect it (scaled to their
    /// totals when `scaled`), and pulls the radiosities (or powers) back up into `out`.
    fn push_pull(&self, id: u32, down: Down, gathered: &Gathered, scaled: bool, out: &mut Field) {
        let node = self.hierarchy.node(id);
        let i = id as usize;
        match self.slot[i] {
            NONE => {
                let down = match down {
                    Down::Irradiance(h) => h,
                    Down::Axes(g) => irradiance_from_axes(&g, node.normal),
                };
                let total = down + gathered.h[i];
                match node.children {
                    None => {
                        let h = if scaled { total * self.scale[i] } else { total };
                        out.irradiance[i] = h;
                        out.incoming[i] = self.incoming(i, total);
                        let b = self.direct[i] + node.reflectance.mul_rgb(h);
                        (out.b[i], out.low[i], out.high[i]) = (b, b, b);
                    }
                    Some(children) => {
                        out.irradiance[i] = total;
                        out.incoming[i] = self.incoming(i, total);
                        for c in children {
                            self.push_pull(c, Down::Irradiance(total), gathered, scaled, out);
                        }
                        self.aggregate(id, out);
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
                for c in node.children.into_iter().flatten() {
                    let down = match self.slot[c as usize] {
                        NONE => Down::Irradiance(irradiance_from_axes(
                            &total,
                            self.hierarchy.node(c).normal,
                        )),
                        _ => Down::Axes(total),
                    };
                    self.push_pull(c, down, gathered, scaled, out);
                }
                self.aggregate(id, out);
            }
        }
    }

    /// The mean radiosity node `i` gathers with unscaled irradiance `h`.
    fn incoming(&self, i: usize, h: Rgb) -> Rgb {
        match self.sums.get(i) {
            Some(&sum) if sum > 0.0 => h / sum,
            _ => Rgb::ZERO,
        }
    }

    /// Node `id`'s light from its children's in `out`: an element's radiosity is their area
    /// mean (and its range theirs), a cluster's power their sum (and its intensities, if it
    /// keeps a table).
    fn aggregate(&self, id: u32, out: &mut Field) {
        let h = self.hierarchy;
        let node = h.node(id);
        let Some(children) = node.children else {
            return;
        };
        match self.slot[id as usize] {
            NONE => {
                let mut sum = Rgb::ZERO;
                let (mut low, mut high) =
                    (Rgb::splat(f64::INFINITY), Rgb::splat(f64::NEG_INFINITY));
                for c in children.map(|c| c as usize) {
                    sum += out.b[c] * h.nodes[c].area;
                    low = low.min(out.low[c]);
                    high = high.max(out.high[c]);
                }
                let i = id as usize;
                (out.b[i], out.low[i], out.high[i]) = (sum / node.area, low, high);
            }
            slot => {
                out.power[slot as usize] = children
                    .iter()
                    .map(|&c| match self.slot[c as usize] {
                        NONE => out.b[c as usize] * h.node(c).area,
                        s => out.power[s as usize],
                    })
                    .sum();
                if let Some(table) = self.table_of(id, out) {
                    out.tables[self.table_slot[id as usize] as usize] = table;
                }
            }
        }
    }

    /// The intensities of cluster `id`, if it keeps a table: its children's tables, or the
    /// surfaces of those that keep none, summed.
    fn table_of(&self, id: u32, out: &Field) -> Option<Table> {
        if self.table_slot[id as usize] == NONE {
            return None;
        }
        let h = self.hierarchy;
        let mut table = directions::DARK;
        let mut stack: Vec<u32> = h.node(id).children.into_iter().flatten().collect();
        while let Some(c) = stack.pop() {
            let node = h.node(c);
            match self.table_slot[c as usize] {
                NONE if node.is_cluster() => stack.extend(node.children.into_iter().flatten()),
                NONE => {
                    directions::add_surface(&mut table, out.b[c as usize] * node.area, node.normal);
                }
                slot => directions::add_table(&mut table, &out.tables[slot as usize]),
            }
        }
        Some(table)
    }

    /// Pulls the leaves' radiosities up the hierarchy from `id`.
    fn pull(&self, id: u32, out: &mut Field) {
        for c in self.hierarchy.node(id).children.into_iter().flatten() {
            self.pull(c, out);
        }
        self.aggregate(id, out);
    }

    /// The coarse correction after a sweep from `before` to `after`: the error is taken to be
    /// uniform, α per channel, with α the residual's area mean over that of (1 − ρT) (the
    /// residual a uniform field of one leaves, T the reflecting part of each leaf's total);
    /// `after` becomes the sweep from `before` + α, which adds α ρ T to each leaf's radiosity.
    pub(super) fn correct(&self, before: &Field, after: &mut Field) {
        let h = self.hierarchy;
        let (mut residual, mut weight) = (Rgb::ZERO, Rgb::ZERO);
        for (i, n) in h.nodes.iter().enumerate() {
            if n.is_leaf() && !n.is_cluster() {
                residual += (after.b[i] - before.b[i]) * n.area;
                weight += (Rgb::splat(1.0) - n.reflectance * self.reflecting[i]) * n.area;
            }
        }
        let alpha = Rgb::new(
            ratio(residual.r, weight.r),
            ratio(residual.g, weight.g),
            ratio(residual.b, weight.b),
        );
        for (i, n) in h.nodes.iter().enumerate() {
            if n.is_cluster() {
                continue;
            }
            after.incoming[i] += alpha;
            if n.is_leaf() {
                let lift = alpha * self.reflecting[i];
                after.irradiance[i] += lift;
                after.b[i] += n.reflectance.mul_rgb(lift);
                (after.low[i], after.high[i]) = (after.b[i], after.b[i]);
            }
        }
        if let Some(root) = h.root {
            self.pull(root, after);
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

/// `a / b`, zero where `b` is not positive.
fn ratio(a: f64, b: f64) -> f64 {
    if b > 0.0 { a / b } else { 0.0 }
}

/// A receiver's total from the form factors found for it: one inside a closed solid, else their
/// sum, at most one.
pub(super) fn bounded(sum: f64, enclosed: bool) -> f64 {
    if enclosed { 1.0 } else { sum.min(1.0) }
}
