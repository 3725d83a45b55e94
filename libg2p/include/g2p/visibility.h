// Symbol visibility: the one macro that marks libg2p's public API. The library
// is built with hidden symbols; every public function and class is marked
// G2P_API. (Before 0.1.0 this header was g2p/export.h, now the export stage's.)
#pragma once

#if defined(G2P_STATIC)
#define G2P_API
#elif defined(_WIN32)
#if defined(G2P_BUILDING)
#define G2P_API __declspec(dllexport)
#else
#define G2P_API __declspec(dllimport)
#endif
#else
#define G2P_API [[gnu::visibility("default")]]
#endif
