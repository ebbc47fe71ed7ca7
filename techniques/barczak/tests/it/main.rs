//! `barczak`'s integration tests, one binary (`cargo test --release -p gibench-barczak --test
//! it`): a module per part; `support` the test room they share.

mod support;

mod database;
mod light_draws;
mod lightmap;
mod lightmap_pass;
mod lowres;
mod passes;
mod prt;
mod prt_pass;
mod renderer;
mod samples;
mod schedule;
mod setup;
mod technique;
mod visibility;
