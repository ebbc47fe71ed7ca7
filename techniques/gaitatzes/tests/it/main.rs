//! `gaitatzes`' integration tests, one binary (`cargo test --release -p gibench-gaitatzes --test
//! it`): the SH transfer and the propagation volume.

mod lpv;
mod transfer;
mod volume;
