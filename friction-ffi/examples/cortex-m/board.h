/* board.h: semihosting output and exit, SysTick (startup.c) */
#ifndef BOARD_H
#define BOARD_H
#include <stdint.h>
void board_puts(const char *s);
void board_exit(int code);
void board_systick_start(void);
uint32_t board_systick(void);
#endif
