/* effects/export.h — what libeffects.so exports. The library is compiled with hidden
 * visibility (-fvisibility=hidden): a function is exported only when one of the public headers
 * declares it, between EFFECTS_API_BEGIN and EFFECTS_API_END (or with EFFECTS_API). Private
 * headers (the .h files beside the sources, their detail:: namespaces, the test hooks) are not exported;
 * tests/install/install_test.sh checks that no detail:: symbol is. The static library links as
 * before. */
#ifndef EFFECTS_EXPORT_H
#define EFFECTS_EXPORT_H

#if defined(__GNUC__) || defined(__clang__)
#define EFFECTS_API __attribute__((visibility("default")))
#define EFFECTS_API_BEGIN _Pragma("GCC visibility push(default)")
#define EFFECTS_API_END _Pragma("GCC visibility pop")
#else
#define EFFECTS_API
#define EFFECTS_API_BEGIN
#define EFFECTS_API_END
#endif

#endif /* EFFECTS_EXPORT_H */
