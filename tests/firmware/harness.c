/*
 * Run the gate-logger firmware in simavr, drive its gate pins with edges at known
 * cycles, and copy its UART to stdout.
 *
 *   harness FIRMWARE.elf EDGES [--speed S] [--lines FILE] [--rx-stdin]
 *
 * EDGES is a text file:
 *   init LLLLLLLL          levels of gates 1..8 before reset (1 = pin high)
 *   CYCLE GATE LEVEL       at CPU cycle CYCLE (16 per us), gate GATE (1..8) goes to LEVEL
 *   CYCLE rx BYTE          at CPU cycle CYCLE the UART receives BYTE (0..255, decimal)
 *   end CYCLE              stop the simulation at this cycle
 * with edges and bytes in time order. Gate 1..6 is PD2..PD7 and gate 7..8 PB0..PB1, as in
 * the firmware.
 *
 * --speed S   pace the output: S simulated seconds per wall-clock second (0, the
 *             default: as fast as the simulation runs).
 * --lines F   write to F, for each UART line, the cycle at which its last byte was sent.
 * --rx-stdin  also pass the bytes that arrive on stdin (e.g. a pty's master end, where
 *             a program writes to the port) to the UART's input, looking every
 *             simulated millisecond.
 *
 * On stderr: "timer1-start-cycle N", the cycle at which the firmware started Timer1
 * (the origin of its tick count), and at the end "cycles N".
 */

#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <simavr/avr_extint.h>
#include <simavr/avr_ioport.h>
#include <simavr/avr_uart.h>
#include <simavr/sim_avr.h>
#include <simavr/sim_elf.h>
#include <simavr/sim_irq.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#define F_CPU 16000000ULL
#define TCCR1B_ADDR 0x81
#define PCICR_ADDR 0x68

typedef struct {
    avr_cycle_count_t cycle;
    int gate;  /* 1..8, or 0: a byte for the UART */
    int level; /* the gate's level, or the byte */
} edge_t;

static edge_t *edges;
static size_t n_edges, next_edge;
static avr_irq_t *gate_irq[8];
static avr_irq_t *uart_in;
static double speed;
static struct timespec wall_start;
static FILE *lines_out;
static char out_buf[256];
static size_t out_len;
static int uart_fd = -1; /* the UART's bytes go here: the process's stdout */
static int rx_stdin;

static void die(const char *what)
{
    fprintf(stderr, "harness: %s\n", what);
    exit(2);
}

static double wall_seconds(void)
{
    struct timespec now;
    clock_gettime(CLOCK_MONOTONIC, &now);
    return (double)(now.tv_sec - wall_start.tv_sec) + 1e-9 * (double)(now.tv_nsec - wall_start.tv_nsec);
}

static void write_all(const char *p, size_t n)
{
    while (n) {
        ssize_t w = write(uart_fd, p, n);
        if (w < 0) {
            if (errno == EINTR)
                continue;
            exit(3); /* the reader went away */
        }
        p += w;
        n -= (size_t)w;
    }
}

static void uart_out(struct avr_irq_t *irq, uint32_t value, void *param)
{
    (void)irq;
    avr_t *avr = param;
    if (out_len < sizeof out_buf)
        out_buf[out_len++] = (char)value;
    if ((char)value != '\n' && out_len < sizeof out_buf)
        return;
    if (speed > 0) {
        double due = (double)avr->cycle / F_CPU / speed;
        double ahead = due - wall_seconds();
        if (ahead > 0) {
            struct timespec nap = {(time_t)ahead, (long)((ahead - (double)(time_t)ahead) * 1e9)};
            nanosleep(&nap, NULL);
        }
    }
    write_all(out_buf, out_len);
    out_len = 0;
    if (lines_out)
        fprintf(lines_out, "%llu\n", (unsigned long long)avr->cycle);
}

/* simavr's own sleep callback waits out a sleeping CPU in real time; the harness paces
   itself (--speed), so a sleep costs nothing here. */
static void no_wait(avr_t *avr, avr_cycle_count_t howlong)
{
    (void)avr;
    (void)howlong;
}

static avr_cycle_count_t apply_edges(avr_t *avr, avr_cycle_count_t when, void *param)
{
    (void)param;
    (void)when;
    while (next_edge < n_edges && edges[next_edge].cycle <= avr->cycle) {
        edge_t *e = &edges[next_edge++];
        avr_raise_irq(e->gate ? gate_irq[e->gate - 1] : uart_in, (uint32_t)e->level);
    }
    return next_edge < n_edges ? edges[next_edge].cycle : 0;
}

static avr_cycle_count_t read_stdin(avr_t *avr, avr_cycle_count_t when, void *param)
{
    (void)avr;
    (void)param;
    struct pollfd p = {STDIN_FILENO, POLLIN, 0};
    unsigned char buf[64];
    if (poll(&p, 1, 0) > 0 && (p.revents & POLLIN)) {
        ssize_t n = read(STDIN_FILENO, buf, sizeof buf);
        for (ssize_t k = 0; k < n; k++)
            avr_raise_irq(uart_in, buf[k]);
    }
    return when + F_CPU / 1000;
}

int main(int argc, char **argv)
{
    if (argc < 3)
        die("usage: harness FIRMWARE.elf EDGES [--speed S] [--lines FILE]");
    for (int i = 3; i < argc; i++) {
        if (!strcmp(argv[i], "--speed") && i + 1 < argc)
            speed = atof(argv[++i]);
        else if (!strcmp(argv[i], "--lines") && i + 1 < argc) {
            lines_out = fopen(argv[++i], "w");
            if (!lines_out)
                die("cannot write --lines file");
        } else if (!strcmp(argv[i], "--rx-stdin"))
            rx_stdin = 1;
        else
            die("unknown option");
    }

    /* simavr prints its own messages on stdout: send them to stderr, keep stdout for
       the UART alone. */
    fflush(stdout);
    uart_fd = dup(STDOUT_FILENO);
    dup2(STDERR_FILENO, STDOUT_FILENO);

    FILE *in = fopen(argv[2], "r");
    if (!in)
        die("cannot read the edges file");
    char init[16] = "11111111";
    unsigned long long end = 0;
    size_t cap = 1024;
    edges = malloc(cap * sizeof *edges);
    char row[128];
    while (fgets(row, sizeof row, in)) {
        unsigned long long c;
        int g, l;
        if (sscanf(row, "init %8s", init) == 1)
            continue;
        if (sscanf(row, "end %llu", &end) == 1)
            continue;
        if (sscanf(row, "%llu rx %d", &c, &l) == 2) {
            if (l < 0 || l > 255)
                die("bad rx line");
            g = 0;
        } else if (sscanf(row, "%llu %d %d", &c, &g, &l) != 3)
            continue;
        else if (g < 1 || g > 8 || (l != 0 && l != 1))
            die("bad edge line");
        if (n_edges && c < edges[n_edges - 1].cycle)
            die("edges out of time order");
        if (n_edges == cap)
            edges = realloc(edges, (cap *= 2) * sizeof *edges);
        edges[n_edges++] = (edge_t){c, g, l};
    }
    fclose(in);
    if (!end)
        die("no 'end CYCLE' line");

    elf_firmware_t fw;
    memset(&fw, 0, sizeof fw);
    if (elf_read_firmware(argv[1], &fw))
        die("cannot read the firmware");
    avr_t *avr = avr_make_mcu_by_name("atmega328p");
    if (!avr)
        die("simavr has no atmega328p");
    avr_init(avr);
    avr_load_firmware(avr, &fw);
    avr->frequency = F_CPU;
    avr->log = 0;
    avr->sleep = no_wait;
    /* Gates 1 and 2 share their pins with INT0/INT1. The firmware leaves those interrupts
       off, but simavr polls a low pin every cycle in their default (low level) mode,
       which would make a sleeping CPU as slow to simulate as a busy one. */
    avr_extint_set_strict_lvl_trig(avr, 0, 0);
    avr_extint_set_strict_lvl_trig(avr, 1, 0);

    uint32_t flags = 0;
    avr_ioctl(avr, AVR_IOCTL_UART_GET_FLAGS('0'), &flags);
    flags &= ~(uint32_t)(AVR_UART_FLAG_STDIO | AVR_UART_FLAG_POLL_SLEEP);
    avr_ioctl(avr, AVR_IOCTL_UART_SET_FLAGS('0'), &flags);
    avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_OUTPUT),
                            uart_out, avr);
    uart_in = avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_INPUT);

    for (int g = 0; g < 8; g++) {
        char port = g < 6 ? 'D' : 'B';
        int pin = g < 6 ? g + 2 : g - 6;
        gate_irq[g] = avr_io_getirq(avr, AVR_IOCTL_IOPORT_GETIRQ(port), pin);
        avr_raise_irq(gate_irq[g], init[g] == '1');
    }
    if (n_edges)
        avr_cycle_timer_register(avr, edges[0].cycle, apply_edges, NULL);
    if (rx_stdin) {
        fcntl(STDIN_FILENO, F_SETFL, fcntl(STDIN_FILENO, F_GETFL) | O_NONBLOCK);
        avr_cycle_timer_register(avr, F_CPU / 1000, read_stdin, NULL);
    }

    clock_gettime(CLOCK_MONOTONIC, &wall_start);
    int timer_seen = 0, pins_set = 0;
    while (avr->cycle < end) {
        int state = avr_run(avr);
        if (state == cpu_Done || state == cpu_Crashed)
            die("the firmware stopped or crashed");
        if (!timer_seen && avr->data[TCCR1B_ADDR]) {
            timer_seen = 1;
            fprintf(stderr, "timer1-start-cycle %llu\n", (unsigned long long)avr->cycle);
        }
        /* simavr lets a write of the pull-up bits (PORTx) set the pin levels; a real
           gate drives its pin regardless, so the levels are set again once the firmware
           has finished its set-up (PCICR written last) and before it reads them. */
        if (!pins_set && avr->data[PCICR_ADDR]) {
            pins_set = 1;
            for (int g = 0; g < 8; g++)
                avr_raise_irq(gate_irq[g], init[g] == '1');
        }
    }
    if (out_len)
        write_all(out_buf, out_len);
    if (lines_out)
        fclose(lines_out);
    fprintf(stderr, "cycles %llu\n", (unsigned long long)avr->cycle);
    return 0;
}
