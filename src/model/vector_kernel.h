#pragma once
// Loops over batches of poses (structure of arrays) are written branch-free for the
// compiler to vectorise. On x86-64 with GCC, such a kernel is compiled twice, for AVX2 (with
// no fused multiply-adds: CMakeLists.txt) and for the baseline, and the loader picks the one
// the CPU runs: the package stays portable and uses AVX2 where it exists. The clone is named
// by the ISA level x86-64-v3 (AVX2, FMA, BMI), whose dispatch tests those features:
// "arch=haswell" is dispatched by CPU model, so every AMD and every later Intel core ran the
// baseline clone. pose_classifier.h's vectorKernelsInUse says which one runs.

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define MOW_VECTOR_CLONE "arch=x86-64-v3"
#define MOW_VECTOR_KERNEL __attribute__((target_clones(MOW_VECTOR_CLONE, "default")))
#else
#define MOW_VECTOR_KERNEL
#endif
