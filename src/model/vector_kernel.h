#pragma once
// Loops over batches of poses (structure of arrays) are written branch-free for the
// compiler to vectorise. On x86-64 with GCC, such a kernel is compiled twice, for AVX2 with
// FMA and for the baseline, and the loader picks the one the CPU runs: the package stays
// portable. As written ("arch=haswell") GCC picks the AVX2 clone by CPU model, on Intel
// Haswell cores only; docs/benchmarks.md, twenty-fourth round, has the fix held back.

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define MOW_VECTOR_KERNEL __attribute__((target_clones("arch=haswell", "default")))
#else
#define MOW_VECTOR_KERNEL
#endif
