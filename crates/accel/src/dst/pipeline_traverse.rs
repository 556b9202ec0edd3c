//! The traversal loop driven only by the hardware pipeline's step function
//! ([`super::pipeline::step`]): the model of the paper's hardware traversal (Lin et al.
//! 2020, §3, Fig. 6), on the software traversal's per-ray state ([`Tracer`]) and stack.

use super::Dst;
use super::pipeline::{PipelineInput, ReturnCode, step};
use super::traverse::{Entry, RunResult, Tracer};
use crate::observer::{NodeStep, Observer};
use dualsplit_geometry::{Hit, Ray};

impl Dst {
    /// Closest hit of `ray`, every node step computed by the pipeline function [`step`].
    pub fn closest_hit_pipeline<O: Observer>(&self, ray: &Ray, obs: &mut O) -> Option<Hit> {
        self.traverse_pipeline::<O, false>(ray, obs)
    }

    /// Any hit of `ray` within `[t_min, t_max]`, driven by the pipeline function [`step`].
    pub fn any_hit_pipeline<O: Observer>(&self, ray: &Ray, obs: &mut O) -> bool {
        self.traverse_pipeline::<O, true>(ray, obs).is_some()
    }

    #[inline(always)]
    fn traverse_pipeline<O: Observer, const ANY: bool>(
        &self,
        ray: &Ray,
        obs: &mut O,
    ) -> Option<Hit> {
        let (mut tr, mut t_min, mut t_max) = Tracer::start(self, ray)?;
        let origin = tr.r.ray.origin.to_array();
        let inv_dir = tr.r.inv_dir.to_array();
        let mut node = 0u32;
        loop {
            let (word, p0, p1) = tr.fetch_node(node, obs);
            let out = step(&PipelineInput {
                word,
                p0,
                p1,
                origin,
                inv_dir,
                t_min,
                t_max,
            });
            obs.step(NodeStep::Dst {
                kind: word.node_kind(),
                outcome: out.code.into(),
                carving_leaf: word.is_carving() & word.is_leaf_flag(),
            });
            match out.code {
                ReturnCode::OneChild => {
                    (node, t_min, t_max) = (out.offset, out.t_min_out, out.t_max_out);
                    continue;
                }
                ReturnCode::BothChildren => {
                    tr.stack.push(Entry {
                        node: out.offset_stack,
                        t_min: out.t_min_out,
                        t_max,
                    });
                    obs.push();
                    (node, t_max) = (out.offset, out.t_max_out);
                    continue;
                }
                ReturnCode::Leaf => {
                    if let RunResult::Occluded = tr.test_run::<O, ANY>(out.offset, obs) {
                        return tr.best;
                    }
                }
                ReturnCode::Miss => {}
            }
            let Some(e) = tr.pop(obs) else {
                return tr.best;
            };
            (node, t_min, t_max) = (e.node, e.t_min, e.t_max);
        }
    }
}
