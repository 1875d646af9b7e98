//! SURF: detection, description, matching and MSAC (being built; see issue 4).
