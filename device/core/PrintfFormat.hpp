// KF_PRINTF_FORMAT(f, a): -Wformat's check of our printf-like functions against the printf the
// build links: MinGW's C99 one (__USE_MINGW_ANSI_STDIO, which knows %zu) where that is it, the
// C library's elsewhere.
#pragma once

#include <cstdio>

#ifdef __MINGW_PRINTF_FORMAT
#define KF_PRINTF_FORMAT(f, a) __attribute__((format(__MINGW_PRINTF_FORMAT, f, a)))
#else
#define KF_PRINTF_FORMAT(f, a) __attribute__((format(printf, f, a)))
#endif
