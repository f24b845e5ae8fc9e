// The gate-logger firmware as an Arduino sketch, for the Arduino IDE: open this file,
// choose the board (Arduino Uno, or Arduino Nano with the processor "ATmega328P" or
// "ATmega328P (Old Bootloader)") and its port, and press Upload.
//
// The firmware itself is gate_logger.c, beside this file: the IDE compiles it with
// the sketch, and its main() replaces the Arduino core's (there is no setup() or
// loop() to write). It prints 8 gates per line; for fewer, add a line such as
// "#define CHANNELS 7" before the first #ifndef in gate_logger.c. docs/logger.md has
// the wiring and the rest.
