# Makes glslangValidator's generated array `static` (one definition per including file) and
# gives it the <stdint.h> it needs.
file(READ "${IN}" text)
string(REPLACE "const uint32_t" "static const uint32_t" text "${text}")
file(WRITE "${OUT}" "#include <stdint.h>\n${text}")
file(REMOVE "${IN}")
