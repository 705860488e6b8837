/*
 * startup.c: the least a bare-metal C program on QEMU's Cortex-M4F needs:
 * a vector table, a reset handler (copy .data, zero .bss, enable the FPU,
 * call main, exit with its code) and semihosting output and exit.
 */
#include <stdint.h>

#include "board.h"

extern uint32_t _data_load, _data_start, _data_end, _bss_start, _bss_end, _stack_top;
int main(void);

/* ARM semihosting call (QEMU: -semihosting-config enable=on) */
static int semihost(int op, const void *arg) {
    register int r0 __asm__("r0") = op;
    register const void *r1 __asm__("r1") = arg;
    __asm__ volatile("bkpt 0xab" : "+r"(r0) : "r"(r1) : "memory");
    return r0;
}

void board_puts(const char *s) { semihost(0x04, s); /* SYS_WRITE0 */ }

void board_exit(int code) {
    /* SYS_EXIT with ADP_Stopped_ApplicationExit (QEMU exits 0) or
       ADP_Stopped_RunTimeErrorUnknown (QEMU exits 1) */
    semihost(0x18, (const void *)(uintptr_t)(code == 0 ? 0x20026 : 0x20023));
    for (;;) {
    }
}

static void fault_handler(void) {
    board_puts("fault\n");
    board_exit(1);
}

void reset_handler(void) {
    uint32_t *src = &_data_load, *dst = &_data_start;
    while (dst < &_data_end) *dst++ = *src++;
    for (dst = &_bss_start; dst < &_bss_end;) *dst++ = 0;
    /* CPACR: full access to CP10 and CP11 (the FPU) */
    *(volatile uint32_t *)0xE000ED88 |= 0xFu << 20;
    __asm__ volatile("dsb\n isb");
    board_exit(main());
}

__attribute__((section(".vectors"), used)) static void (*const vectors[16])(void) = {
    (void (*)(void))&_stack_top, reset_handler, fault_handler, fault_handler,
    fault_handler, fault_handler, fault_handler, 0, 0, 0, 0,
    fault_handler, fault_handler, 0, fault_handler, fault_handler,
};

/* SysTick: 24 bits, counting down from 0xFFFFFF at the core clock */
#define SYST_CSR (*(volatile uint32_t *)0xE000E010)
#define SYST_RVR (*(volatile uint32_t *)0xE000E014)
#define SYST_CVR (*(volatile uint32_t *)0xE000E018)

void board_systick_start(void) {
    SYST_RVR = 0x00FFFFFF;
    SYST_CVR = 0;
    SYST_CSR = 5; /* enable, core clock, no interrupt */
}

uint32_t board_systick(void) { return SYST_CVR; }

/* the freestanding helpers gcc may call */
void *memcpy(void *d, const void *s, unsigned n) {
    unsigned char *a = d;
    const unsigned char *b = s;
    while (n--) *a++ = *b++;
    return d;
}

void *memset(void *d, int c, unsigned n) {
    unsigned char *a = d;
    while (n--) *a++ = (unsigned char)c;
    return d;
}
