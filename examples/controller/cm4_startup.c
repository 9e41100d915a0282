/* Minimal Cortex-M4F start-up for running the controller under
   qemu-system-arm -M mps2-an386 with semihosting: a vector table at address 0,
   a reset handler that enables the FPU and enters newlib's _start (rdimon
   crt0: sets up the C runtime via semihosting, calls main, then exit). */
extern void _start(void);
extern unsigned long __stack_top__;

void cm4_reset(void);
void cm4_reset(void) {
  /* CPACR: full access to CP10 and CP11 (the FPU) */
  *(volatile unsigned long *)0xE000ED88UL |= (0xFUL << 20);
  __asm volatile("dsb\n isb");
  _start();
  for (;;) {}
}

static void cm4_fault(void) { for (;;) {} }

__attribute__((section(".vectors"), used)) void (*const cm4_vectors[16])(void) = {
  (void (*)(void))(&__stack_top__), cm4_reset, cm4_fault, cm4_fault, cm4_fault, cm4_fault, cm4_fault,
  0, 0, 0, 0, cm4_fault, cm4_fault, 0, cm4_fault, cm4_fault};
