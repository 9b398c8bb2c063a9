//! What a share link may ask of a page that opens it. A link is a stranger's input: each
//! setting that multiplies a frame's work or the tree's memory (rays, hits kept, steps,
//! bisection iterations, tree levels, node budget, certified cells, brute force) is lowered
//! to a bound near its default, so that the first picture of any link costs about what the
//! default scene costs, on a software adapter too, and what was lowered is said. The
//! panel's controls still reach the full ranges of [`limits`](super::limits): a user raises
//! a setting by hand.

use super::link::LinkProblem;
use super::settings::Scene;

/// The most a link may ask of each setting that sets the work of a frame or of the tree.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinkBounds {
    pub rays: u32,
    pub hits: u32,
    pub steps: u32,
    pub bisection_iters: u32,
    pub max_level: u32,
    pub min_level: u32,
    pub node_budget: u32,
    pub cert_budget: u32,
    /// Whether a link may ask for brute force (every ray marched across the domain with the
    /// finest leaves' step: hundreds of times a frame's work).
    pub brute_force: bool,
}

/// A web page's bounds: the chapter's most rays (fig. 3.12's 100), twice the default hits
/// and steps; the default tree's levels plus two (min one) and its node budget; the
/// default certified budget. Every example is within them.
pub const PAGE_LINK_BOUNDS: LinkBounds = LinkBounds {
    rays: 100,
    hits: 8,
    steps: 16,
    bisection_iters: 32,
    max_level: 8,
    min_level: 5,
    node_budget: 2_000_000,
    cert_budget: super::limits::DEFAULT_CERT_BUDGET,
    brute_force: false,
};

impl Scene {
    /// Lowers every setting above `bounds` to it; what was lowered, as one problem that
    /// names each key with the link's value and the one drawn (None: nothing was).
    pub fn bounded(&mut self, bounds: &LinkBounds) -> Option<LinkProblem> {
        let mut lowered = Vec::new();
        let mut lower = |key: &str, value: &mut u32, most: u32| {
            if *value > most {
                lowered.push(format!("{key} {value} → {most}"));
                *value = most;
            }
        };
        let (render, tree) = (&mut self.render, &mut self.tree);
        lower("render.rays", &mut render.rays, bounds.rays);
        lower("render.hits", &mut render.hits, bounds.hits);
        lower("render.steps", &mut render.steps, bounds.steps);
        lower(
            "render.bisection_iters",
            &mut render.bisection_iters,
            bounds.bisection_iters,
        );
        lower(
            "render.cert_budget",
            &mut render.cert_budget,
            bounds.cert_budget,
        );
        lower("tree.max_level", &mut tree.max_level, bounds.max_level);
        lower("tree.min_level", &mut tree.min_level, bounds.min_level);
        lower(
            "tree.node_budget",
            &mut tree.node_budget,
            bounds.node_budget,
        );
        if render.brute_force && !bounds.brute_force {
            render.brute_force = false;
            lowered.push("render.brute_force true → false".into());
        }
        (!lowered.is_empty()).then(|| LinkProblem {
            key: lowered.join(", "),
            message: "lowered for this page, so that a link's first picture stays within a \
                      fixed amount of work; raise them in the panel"
                .into(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_heavy_link_is_lowered_key_by_key_and_a_light_one_kept() {
        let (mut heavy, problems) = Scene::from_link(
            "#formula=x%5E2%2By%5E2%2Bz%5E2%2Bw%5E2-1&render.rays=1024&render.hits=16\
             &tree.max_level=12&tree.min_level=12&tree.node_budget=100000000\
             &render.steps=256&render.bisection_iters=256&render.brute_force=true\
             &render.cert_budget=8192",
            &Scene::from_formula("x"),
        );
        assert!(problems.is_empty(), "{problems:?}");
        let lowered = heavy.bounded(&PAGE_LINK_BOUNDS).unwrap();
        assert_eq!(
            lowered.to_string(),
            "in the link, render.rays 1024 → 100, render.hits 16 → 8, render.steps 256 → 16, \
             render.bisection_iters 256 → 32, render.cert_budget 8192 → 2048, \
             tree.max_level 12 → 8, tree.min_level 12 → 5, tree.node_budget 100000000 → \
             2000000, render.brute_force true → false: lowered for this page, so that a \
             link's first picture stays within a fixed amount of work; raise them in the panel"
        );
        assert_eq!((heavy.render.rays, heavy.tree.max_level), (100, 8));
        assert!(heavy.check().is_ok());
        for light in [
            Scene::from_formula("x - y"),
            Scene::example("fig-3-9-left").unwrap(),
        ] {
            let mut kept = light.clone();
            assert_eq!(kept.bounded(&PAGE_LINK_BOUNDS), None);
            assert_eq!(kept, light);
        }
    }

    #[test]
    fn every_example_fits_the_page_s_bounds() {
        for (name, _) in super::super::EXAMPLES {
            let mut scene = Scene::example(name).unwrap();
            assert_eq!(scene.bounded(&PAGE_LINK_BOUNDS), None, "{name}");
        }
    }
}
