//! The integration tests of `sim` as one test binary (its modules are the files beside this
//! one, each as it was a binary of its own), so that a cold `cargo test` compiles and links the
//! library's generic code once instead of once per file, and the tests of every file share the
//! test harness's threads. Files that must stay binaries of their own (a counting global
//! allocator) are `[[test]]` targets of their own in `Cargo.toml`; the root package's test
//! `e2e::test_binaries` fails if a file of `tests/` is in neither place, so no test file can
//! silently stop running.

mod contacts_support;
#[path = "arms_load.rs"]
mod arms_load;
#[path = "bad_input.rs"]
mod bad_input;
#[path = "by_hand.rs"]
mod by_hand;
#[path = "contact_friction_topic.rs"]
mod contact_friction_topic;
#[path = "contact_shapes.rs"]
mod contact_shapes;
#[path = "contacts_chatter.rs"]
mod contacts_chatter;
#[path = "contacts_converge.rs"]
mod contacts_converge;
#[path = "contacts_idle.rs"]
mod contacts_idle;
#[path = "contacts_ladder.rs"]
mod contacts_ladder;
#[path = "contacts_exact.rs"]
mod contacts_exact;
#[path = "contacts_pair.rs"]
mod contacts_pair;
#[path = "contacts_paper.rs"]
mod contacts_paper;
#[path = "contacts_pendulum.rs"]
mod contacts_pendulum;
#[path = "contacts_point.rs"]
mod contacts_point;
#[path = "contacts_recording.rs"]
mod contacts_recording;
#[path = "contacts_real_arms.rs"]
mod contacts_real_arms;
#[path = "contacts_rod.rs"]
mod contacts_rod;
#[path = "contacts_seesaw.rs"]
mod contacts_seesaw;
#[path = "contacts_scene.rs"]
mod contacts_scene;
#[path = "contacts_start.rs"]
mod contacts_start;
#[path = "contacts_steps.rs"]
mod contacts_steps;
#[path = "convergence.rs"]
mod convergence;
#[path = "current_columns.rs"]
mod current_columns;
#[path = "current_columns_cases.rs"]
mod current_columns_cases;
#[path = "drive_features.rs"]
mod drive_features;
#[path = "drives.rs"]
mod drives;
#[path = "drives_support.rs"]
mod drives_support;
#[path = "fuzz_scenes.rs"]
mod fuzz_scenes;
#[path = "gear_band.rs"]
mod gear_band;
#[path = "gear_supply.rs"]
mod gear_supply;
#[path = "hand_load.rs"]
mod hand_load;
#[path = "hybrid_jacobian.rs"]
mod hybrid_jacobian;
#[path = "hard_cases.rs"]
mod hard_cases;
#[path = "paper.rs"]
mod paper;
#[path = "physics.rs"]
mod physics;
#[path = "properties.rs"]
mod properties;
#[path = "recording.rs"]
mod recording;
#[path = "reductions.rs"]
mod reductions;
#[path = "rng_support.rs"]
mod rng_support;
#[path = "robot_spec.rs"]
mod robot_spec;
#[path = "runaway.rs"]
mod runaway;
#[path = "stiff_methods.rs"]
mod stiff_methods;
#[path = "thermal.rs"]
mod thermal;
#[path = "targets.rs"]
mod targets;
#[path = "urdf_corpus.rs"]
mod urdf_corpus;

