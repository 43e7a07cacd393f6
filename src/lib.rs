pub mod contact;
pub mod dynamics;
pub mod integrate;
pub mod params;
pub mod reference;
