#pragma once

namespace partita {
/// The partita version string ("major.minor.patch").
const char* version();
}  // namespace partita
