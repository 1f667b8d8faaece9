// Forwarding header: the typed errors live in base/errors.hpp, below both io/ and
// engine/. Kept so that files not yet moved over keep building; include base/errors.hpp.
#pragma once
#include "base/errors.hpp"
