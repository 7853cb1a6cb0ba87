// f32_lat.vh -- pipeline latencies of the arithmetic units, in clocks from an input
// sample to the output holding its result, for the pipeline configuration in
// pipe.vh (PIPE_S: each inner stage a register; PIPE_U: each unit's output a
// register). `include inside a module body, after tfb_params.vh where the TFB's
// latencies are used (they take ITER). Every unit accepts one new operand set per
// clock; no valid/ready. The model's copy of these formulas is
// tactile_rtl::text::Pipeline::latency: the co-simulation holds both to the clocks.
`include "pipe.vh"
`ifndef TACTILE_LAT_VH
`define TACTILE_LAT_VH
// The TFB's latencies for ITER iterations (macros: a TFB takes ITER as a parameter,
// a module from tfb_params.vh). tfb_sincos: unpack, reduce, fold, the iterations,
// saturate, then its output; tfb_vector: unpack, fold, the iterations, offset, then
// its output; tfb_sqrt1m: 32 stages and its output; tfb_acos: tfb_sqrt1m, then
// tfb_vector.
`define TFB_SINCOS_LAT(iter) (((iter) + 4) * PIPE_S + PIPE_U)
`define TFB_VECTOR_LAT(iter) (((iter) + 3) * PIPE_S + PIPE_U)
`define TFB_SQRT1M_LAT (32 * PIPE_S + PIPE_U)
`define TFB_ACOS_LAT(iter) (`TFB_SQRT1M_LAT + `TFB_VECTOR_LAT(iter))
`endif
// f32_add, f32_mul: 3 inner stages and the output; f32_div, f32_sqrt: 27.
localparam integer F32_ADD_LAT  = 3 * PIPE_S + PIPE_U;
localparam integer F32_MUL_LAT  = 3 * PIPE_S + PIPE_U;
localparam integer F32_DIV_LAT  = 27 * PIPE_S + PIPE_U;
localparam integer F32_SQRT_LAT = 27 * PIPE_S + PIPE_U;
