pub mod contact;
pub mod dynamics;
pub mod error;
pub mod integrate;
pub mod params;
pub mod reference;
pub mod walk;
pub mod output;
