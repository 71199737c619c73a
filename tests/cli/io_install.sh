#!/usr/bin/env bash
# `make install` works for users: install the build tree into a temporary
# prefix, then build and run a small program against the installed library
# twice, once through pkg-config and once through CMake's find_package.
. "$(dirname "$0")/lib/common.sh" "$@"
BUILD=$(cd "$(dirname "$SPN")" && pwd)
[ -f "$BUILD/cmake_install.cmake" ] || fail "$BUILD is not a CMake build folder"
PREFIX=$T/prefix

cmake --install "$BUILD" --prefix "$PREFIX" >"$T/install.log" 2>&1 || fail "cmake --install: $(tail -5 "$T/install.log")"
[ -x "$PREFIX/bin/spinneret" ] || fail "program not installed"
[ -f "$PREFIX/include/spinneret/spinneret.h" ] || fail "headers not installed"
"$PREFIX/bin/spinneret" --version | grep -q '^spinneret ' || fail "installed program does not run"

# A sanitized build installs a sanitized library: its users need the same
# flags, and the same compiler (its sanitizer runtime).
EXTRA=""
grep -q '^SPN_SANITIZE:BOOL=ON' "$BUILD/CMakeCache.txt" && EXTRA="-fsanitize=address,undefined"
CC=$(sed -n 's/^CMAKE_C_COMPILER:[A-Z]*=//p' "$BUILD/CMakeCache.txt")
export CC=${CC:-cc}

mkdir "$T/app"
cat >"$T/app/main.c" <<'C'
/* Build a two-particle world, save it, load it back, check the count. */
#include <spinneret/spinneret.h>
#include <stdio.h>
int main(int argc, char **argv)
{
    spn_world *w = spn_world_create(NULL);
    spn_particle_def p = spn_particle_def_default();
    uint32_t a, b;
    spn_world_add_particle(w, &p, &a);
    p.position.x = 1;
    spn_world_add_particle(w, &p, &b);
    spn_spring_def s = spn_spring_def_default();
    s.a = a;
    s.b = b;
    spn_world_add_spring(w, &s, NULL);
    spn_world_step(w, 1e-3); /* links the stepping code, with OpenMP */
    spn_world *back = NULL;
    int ok = argc > 1 && spn_web_save(w, argv[1]) == SPN_OK && spn_web_load(argv[1], &back) == SPN_OK &&
             spn_world_particle_count(back) == 2 && spn_world_spring_count(back) == 1;
    printf("spinneret %s: %s\n", spn_version(), ok ? "round trip ok" : spn_last_error());
    spn_world_destroy(w);
    spn_world_destroy(back);
    return ok ? 0 : 1;
}
C

# 1. pkg-config (the shared library, found at run time through LD_LIBRARY_PATH).
PCDIR=$(dirname "$(find "$PREFIX" -name spinneret.pc | head -1)")
[ -f "$PCDIR/spinneret.pc" ] || fail "spinneret.pc not installed"
FLAGS=$(PKG_CONFIG_PATH=$PCDIR pkg-config --cflags --libs spinneret) || fail "pkg-config cannot read spinneret.pc"
case "$FLAGS" in *"$PREFIX"*) ;; *) fail "pkg-config flags do not point into the prefix: $FLAGS" ;; esac
"$CC" -std=c11 -Wall -Werror $EXTRA "$T/app/main.c" -o "$T/app/pc" $FLAGS 2>"$T/err" || fail "compile with pkg-config: $(cat "$T/err")"
LD_LIBRARY_PATH=$(PKG_CONFIG_PATH=$PCDIR pkg-config --variable=libdir spinneret) "$T/app/pc" "$T/app/pc.json" \
    | grep -q 'round trip ok' || fail "pkg-config program failed"
# ... and statically, with the private dependencies (the archive in place of
# -lspinneret, which the linker would otherwise resolve to the shared library).
SFLAGS=$(PKG_CONFIG_PATH=$PCDIR pkg-config --static --cflags --libs spinneret)
LIBDIR=$(PKG_CONFIG_PATH=$PCDIR pkg-config --variable=libdir spinneret)
SFLAGS=${SFLAGS//-lspinneret/$LIBDIR/libspinneret.a}
"$CC" -std=c11 $EXTRA "$T/app/main.c" -o "$T/app/pc-static" $SFLAGS 2>"$T/err" \
    || fail "static link with pkg-config --static: $(cat "$T/err")"
"$T/app/pc-static" "$T/app/st.json" | grep -q 'round trip ok' || fail "static pkg-config program failed"

# 2. CMake: find_package(spinneret) and the spinneret::spinneret target.
cat >"$T/app/CMakeLists.txt" <<CM
cmake_minimum_required(VERSION 3.18)
project(app LANGUAGES C)
find_package(spinneret 0.1 REQUIRED)
add_executable(app main.c)
target_link_libraries(app PRIVATE spinneret::spinneret)
CM
cmake -S "$T/app" -B "$T/app/build" -DCMAKE_PREFIX_PATH="$PREFIX" -DCMAKE_C_COMPILER="$CC" -DCMAKE_C_FLAGS="$EXTRA" \
      -DCMAKE_EXE_LINKER_FLAGS="$EXTRA" >"$T/cmake.log" 2>&1 \
    || fail "find_package(spinneret): $(tail -15 "$T/cmake.log")"
cmake --build "$T/app/build" >"$T/build.log" 2>&1 || fail "build with find_package: $(tail -15 "$T/build.log")"
"$T/app/build/app" "$T/app/cm.json" | grep -q 'round trip ok' || fail "find_package program failed"
echo "io_install ok"
