pub mod reconstruct;
