// f32_lat.vh -- pipeline latencies of the IEEE-754 binary32 units
// (f32_add, f32_mul, f32_div, f32_sqrt): clocks from an input sample to
// the output register holding its result. `include inside a module body.
// Every unit accepts one new operand set per clock; no valid/ready.
localparam integer F32_ADD_LAT  = 4;
localparam integer F32_MUL_LAT  = 4;
localparam integer F32_DIV_LAT  = 28;
localparam integer F32_SQRT_LAT = 28;
