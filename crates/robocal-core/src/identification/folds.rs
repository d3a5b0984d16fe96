//! The folds of a model selection's cross-validation: by pose, so that the rows of one pose
//! (several reflectors, 6-DoF rows) stay together.

use crate::model::MAX_JOINTS;
use crate::observations::Observations;
use rand::seq::SliceRandom;
use rand::SeedableRng;
use std::collections::HashMap;

/// Folds of the cross-validation.
pub const FOLDS: usize = 5;

/// The fold (0..folds) of each observation: the distinct poses (joint values) in a seeded
/// random order, dealt out in turn, so that the rows of one pose share a fold.
pub fn pose_folds(obs: &Observations, folds: usize) -> Vec<usize> {
    let mut pose_of = Vec::with_capacity(obs.len());
    let mut index: HashMap<[u64; MAX_JOINTS], usize> = HashMap::with_capacity(obs.len());
    for i in 0..obs.len() {
        let mut key = [0u64; MAX_JOINTS];
        for (k, v) in key.iter_mut().zip(obs.q(i)) {
            *k = v.to_bits();
        }
        let n = index.len();
        pose_of.push(*index.entry(key).or_insert(n));
    }
    let mut order: Vec<usize> = (0..index.len()).collect();
    order.shuffle(&mut rand_chacha::ChaCha8Rng::seed_from_u64(0x5eed));
    let mut fold_of_pose = vec![0; order.len()];
    for (k, &p) in order.iter().enumerate() {
        fold_of_pose[p] = k % folds.max(1);
    }
    pose_of.into_iter().map(|p| fold_of_pose[p]).collect()
}
