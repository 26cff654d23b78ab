// Built only by the test Layering.AnUpwardIncludeFailsTheBuild, with the io library's view of
// src/: file formats sit below the growth methods, so this include must not compile.
#include "grow/method.hpp"
