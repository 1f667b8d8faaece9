// [material.fracture] tables the tests share, as case text to append to a [[material]].
#pragma once

namespace fdem::test {

// The tests' fracturable rock on tests/data/cases/bar.geo: breaks under a pull of a few
// MPa (tensile strength 2 MPa, G_f 20 / 200 J/m²).
inline const char* const kRockFracture = R"(
[material.fracture]
tensile_strength = 2e6
cohesion = 10e6
friction_angle = 30.0
gf1 = 20.0
gf2 = 200.0
penalty = { opening = 100e9, sliding = 100e9, overlap = 100e9 }
)";

// Ten times stronger, with a hundred times the fracture energy: rock that stays whole
// while weak [[interface]]s beside it break (the three-part bars of the breaks and
// fragments tests).
inline const char* const kStrongFracture = R"(
[material.fracture]
tensile_strength = 20e6
cohesion = 40e6
friction_angle = 30.0
gf1 = 200.0
gf2 = 2000.0
penalty = { opening = 100e9, sliding = 100e9, overlap = 100e9 }
)";

}  // namespace fdem::test
