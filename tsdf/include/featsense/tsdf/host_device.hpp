#pragma once
/// Marks functions that both the CPU integrator and the CUDA kernels call, so the TSDF rule
/// is written once: one definition, two backends.

#if defined(__CUDACC__)
#define FEATSENSE_HD __host__ __device__
#define FEATSENSE_HD_INLINE __host__ __device__ __forceinline__
#else
#define FEATSENSE_HD
#define FEATSENSE_HD_INLINE inline
#endif
