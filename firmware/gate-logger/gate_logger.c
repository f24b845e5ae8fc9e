/*
 * gate-logger: a light-gate logger for metrosync (ATmega328P at 16 MHz: Arduino Uno or Nano).
 *
 * Contract (docs/logger.md has the wiring, the parts and the reasons):
 *
 *   Gates     up to 8 inputs, read together: gate 1..6 on PD2..PD7 (Arduino D2..D7),
 *             gate 7..8 on PB0..PB1 (D8..D9). PD0/PD1 stay the UART. Internal pull-ups
 *             are on, so an unwired gate reads a steady 1. CHANNELS (1..8) sets how many
 *             gates are read and printed.
 *   Clock     Timer1 at 16 MHz / 1024 = 64 us per tick; its 16-bit count is extended in
 *             software by a 16-bit overflow count to 32 bits, which wraps after
 *             2^32 ticks = 274 877.9 s = 76.4 h.
 *   Debounce  a gate's change is timestamped at its first edge; further changes of that
 *             gate are ignored for a hold-off of HOLDOFF_TICKS ticks (4 ticks: between
 *             192 and 256 us, the first tick being partial). When the hold-off ends, a
 *             level that differs from the one reported is reported then, at that time.
 *             So bounce never delays or shifts the first edge, and a spike shorter than
 *             the hold-off shows as a spell of one hold-off (metrosync drops spells
 *             shorter than 0.5 ms as glitches).
 *   Output    8N1 at BAUD (115200) baud, lines ending CR LF:
 *               "# metrosync gate-logger 1.1 channels=8 tick_us=64 counter_bits=32
 *                baud=115200 holdoff_ticks=4"        once at start-up (one line), then
 *               "0-0-1-0-0-0-0-0 1450"               the levels at start-up, then one
 *                                                    line per change of any gate: gate 1
 *                                                    first, 1 = pin high, the counter in
 *                                                    ticks (decimal);
 *               "# overflow: 12 records lost"        where records (changes of one or more
 *                                                    gates) were lost because the buffer
 *                                                    was full, at their place, followed
 *                                                    by a record of the levels as they
 *                                                    were when there was room again.
 *   Input     a '?' received on the serial line asks for the header again: it is sent
 *             as the next line, with " requested=1" at its end, so that a program that
 *             opened the port without resetting the board (and so missed the first
 *             header) can still learn the gate count, tick and counter width; the
 *             added key tells it from the header of a restart. Other bytes are ignored.
 *   Buffering changes queue in a ring of RING_EVENTS (128) records drained by the UART,
 *             so a burst waits instead of being lost; only a ring that fills drops
 *             records, and the overflow line then says how many.
 *
 * START_TICKS (default 0) starts the counter elsewhere: only the tests set it, to reach
 * the 32-bit wrap in seconds instead of 76 hours.
 */

#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/sleep.h>
#include <stdint.h>
#include <stdlib.h>

#ifndef F_CPU
#define F_CPU 16000000UL
#endif
#ifndef BAUD
#define BAUD 115200
#endif
#ifndef CHANNELS
#define CHANNELS 8
#endif
#ifndef HOLDOFF_TICKS
#define HOLDOFF_TICKS 4
#endif
#ifndef RING_EVENTS
#define RING_EVENTS 128
#endif
#ifndef START_TICKS
#define START_TICKS 0UL
#endif

#define VERSION "1.1"
#define HEADER_REQUEST '?'
#define STR_(x) #x
#define STR(x) STR_(x)

#if F_CPU != 16000000UL
#error "the 64 us tick needs F_CPU = 16 MHz (16 MHz / 1024)"
#endif
#if CHANNELS < 1 || CHANNELS > 8
#error "CHANNELS must be 1..8"
#endif
#if RING_EVENTS < 2 || RING_EVENTS > 128 || (RING_EVENTS & (RING_EVENTS - 1))
#error "RING_EVENTS must be a power of two in 2..128"
#endif

/* 115200 baud from 16 MHz is 2.1 % fast with U2X (UBRR 16): well inside what 8N1 takes. */
#define BAUD_TOL 3
#include <util/setbaud.h>

#define GATE_MASK ((uint8_t)((1u << CHANNELS) - 1u))
#define PORTD_GATES ((uint8_t)((GATE_MASK & 0x3Fu) << 2)) /* gates 1..6 -> PD2..PD7 */
#define PORTB_GATES ((uint8_t)(GATE_MASK >> 6))            /* gates 7..8 -> PB0..PB1 */

enum { KIND_CHANGE, KIND_OVERFLOW };

typedef struct {
    uint32_t value; /* ticks of a change, or the count of records lost */
    uint8_t levels;
    uint8_t kind;
} record_t;

static volatile uint16_t ticks_high; /* Timer1 overflows: the counter's upper 16 bits */

/* Shared between the pin-change interrupts and the main loop; changed only with
   interrupts off. */
static record_t ring[RING_EVENTS];
static volatile uint8_t head, tail; /* free-running; head - tail records queued */
static uint8_t reported;            /* levels of the last change queued */
static uint8_t holding;             /* gates inside their hold-off */
static uint16_t since[8];           /* low 16 bits of the tick each hold-off began */
static uint32_t lost;               /* records dropped since the last overflow record */

/* The line being sent, drained byte by byte by the UART interrupt. */
static char line[128];
static volatile uint8_t line_len, line_pos;
static volatile uint8_t header_requested; /* a HEADER_REQUEST byte came in */

static inline uint8_t read_gates(void)
{
    /* Back to back, 1 cycle apart; again if port D changed in between, so that edges
       on both ports at one instant are read together (one line), never split. */
    uint8_t d, b;
    do {
        d = PIND;
        b = PINB;
    } while (d != PIND);
    return (uint8_t)(((d >> 2) & 0x3Fu) | ((b & 0x03u) << 6)) & GATE_MASK;
}

/* The 32-bit tick count; interrupts must be off. */
static uint32_t now_ticks(void)
{
    uint16_t lo = TCNT1;
    uint16_t hi = ticks_high;
    /* An overflow not yet serviced: TCNT1 has wrapped but ticks_high has not counted it. */
    if ((TIFR1 & _BV(TOV1)) && lo < 0x8000u)
        hi++;
    return ((uint32_t)hi << 16) | lo;
}

static void put(uint8_t kind, uint8_t levels, uint32_t value)
{
    record_t *r = &ring[head & (RING_EVENTS - 1)];
    r->value = value;
    r->levels = levels;
    r->kind = kind;
    head++;
}

/* Queue a change; interrupts must be off. After a loss the overflow record goes first,
   so it needs two free places and sits in the stream where the records were lost. */
static void push(uint8_t levels, uint32_t ticks)
{
    uint8_t used = (uint8_t)(head - tail);
    uint8_t need = lost ? 2 : 1;
    if ((uint8_t)(RING_EVENTS - used) < need) {
        if (lost != 0xFFFFFFFFu)
            lost++;
        return;
    }
    if (lost) {
        put(KIND_OVERFLOW, 0, lost);
        lost = 0;
    }
    put(KIND_CHANGE, levels, ticks);
}

/* Look at the gates: end the hold-offs that are over, and queue a change of any gate
   not in its hold-off, timestamped now. Interrupts must be off. */
static void sample(void)
{
    /* The pins before the clock: an edge then always gets its own tick or the next,
       never the tick before it (which a tick boundary between the two reads gave). */
    uint8_t pins = read_gates();
    uint32_t t = now_ticks();
    uint8_t h = holding;
    if (h) {
        for (uint8_t k = 0; k < CHANNELS; k++) {
            uint8_t bit = (uint8_t)(1u << k);
            if ((h & bit) && (uint16_t)((uint16_t)t - since[k]) >= HOLDOFF_TICKS)
                h &= (uint8_t)~bit;
        }
    }
    uint8_t changed = (uint8_t)((pins ^ reported) & ~h);
    if (changed) {
        reported ^= changed;
        h |= changed;
        for (uint8_t k = 0; k < CHANNELS; k++)
            if (changed & (1u << k))
                since[k] = (uint16_t)t;
        push(reported, t);
    }
    holding = h;
}

ISR(PCINT2_vect) { sample(); }
ISR(PCINT0_vect, ISR_ALIASOF(PCINT2_vect));
ISR(TIMER1_OVF_vect) { ticks_high++; }

ISR(USART_UDRE_vect)
{
    if (line_pos < line_len)
        UDR0 = (uint8_t)line[line_pos++];
    if (line_pos >= line_len)
        UCSR0B &= (uint8_t)~_BV(UDRIE0); /* line sent: the main loop sets up the next */
}

ISR(USART_RX_vect)
{
    uint8_t status = UCSR0A;
    uint8_t c = UDR0; /* read in any case: it clears the interrupt */
    if (c == HEADER_REQUEST && !(status & (_BV(FE0) | _BV(DOR0))))
        header_requested = 1;
}

static uint8_t append(uint8_t n, const char *s)
{
    while (*s && n < sizeof line - 3)
        line[n++] = *s++;
    return n;
}

static void send_line(uint8_t n)
{
    line[n++] = '\r';
    line[n++] = '\n';
    cli();
    line_pos = 0;
    line_len = n;
    UCSR0B |= _BV(UDRIE0);
    sei();
}

static void format(const record_t *r)
{
    char digits[11];
    uint8_t n = 0;
    ultoa(r->value, digits, 10);
    if (r->kind == KIND_OVERFLOW) {
        n = append(n, "# overflow: ");
        n = append(n, digits);
        n = append(n, " records lost");
    } else {
        for (uint8_t k = 0; k < CHANNELS; k++) {
            if (k)
                line[n++] = '-';
            line[n++] = (r->levels & (1u << k)) ? '1' : '0';
        }
        line[n++] = ' ';
        n = append(n, digits);
    }
    send_line(n);
}

static void setup(void)
{
    /* The clock first: it starts the time base everything else is measured on. */
    TCCR1A = 0;
    TIFR1 = _BV(TOV1);
    TIMSK1 = _BV(TOIE1);
    TCCR1B = _BV(CS12) | _BV(CS10); /* clk / 1024 */
#if START_TICKS
    /* After the start: simavr forgets a count written to a stopped timer. */
    TCNT1 = (uint16_t)(START_TICKS & 0xFFFFu);
    ticks_high = (uint16_t)(START_TICKS >> 16);
#endif

    DDRD &= (uint8_t)~PORTD_GATES; /* inputs with pull-ups */
    PORTD |= PORTD_GATES;
    DDRB &= (uint8_t)~PORTB_GATES;
    PORTB |= PORTB_GATES;

#if USE_2X /* before UBRR0: simavr derives its byte time when UBRR0 is written */
    UCSR0A = _BV(U2X0);
#else
    UCSR0A = 0;
#endif
    UBRR0H = UBRRH_VALUE;
    UBRR0L = UBRRL_VALUE;
    UCSR0C = _BV(UCSZ01) | _BV(UCSZ00); /* 8N1 */
    UCSR0B = _BV(TXEN0) | _BV(RXEN0) | _BV(RXCIE0);

    PCMSK2 = PORTD_GATES;
    PCMSK0 = PORTB_GATES;
    PCIFR = _BV(PCIF2) | _BV(PCIF0);
    PCICR = (PORTD_GATES ? _BV(PCIE2) : 0) | (PORTB_GATES ? _BV(PCIE0) : 0);
}

#define HEADER "# metrosync gate-logger " VERSION " channels=" STR(CHANNELS) \
               " tick_us=64 counter_bits=32 baud=" STR(BAUD) " holdoff_ticks=" STR(HOLDOFF_TICKS)

int main(void)
{
    setup();
    /* The levels at start-up are the first record, queued before any change can be. */
    reported = read_gates();
    put(KIND_CHANGE, reported, now_ticks());
    sei();
    send_line(append(0, HEADER));
    set_sleep_mode(SLEEP_MODE_IDLE);
    for (;;) {
        cli();
        sample(); /* ends hold-offs, and reports a level a hold-off hid */
        if (lost && (uint8_t)(RING_EVENTS - (uint8_t)(head - tail)) >= 2) {
            /* Room again: say what was lost, and give the levels as they are now, so the
               stream is right again even if no gate changes for a while. */
            put(KIND_OVERFLOW, 0, lost);
            lost = 0;
            put(KIND_CHANGE, reported, now_ticks());
        }
        uint8_t busy = line_pos < line_len;
        if (!busy && header_requested) {
            /* Before the queued records: the header carries no time, and the program
               that asked waits for it to read them. */
            header_requested = 0;
            sei();
            send_line(append(0, HEADER " requested=1"));
            continue;
        }
        if (!busy && head != tail) {
            record_t r = ring[tail & (RING_EVENTS - 1)];
            tail++;
            sei();
            format(&r);
            continue;
        }
        if (holding) {
            /* A hold-off is running: keep looking until it ends, with interrupts open
               for a few cycles each time round (simavr takes one only two instructions
               after sei, the chip after one). */
            sei();
            __asm__ __volatile__("nop\n\tnop\n\tnop" ::: "memory");
            continue;
        }
        /* Nothing to do until a gate, the timer or the UART interrupts. sei takes effect
           after the next instruction, so no interrupt slips in before the sleep. */
        sleep_enable();
        sei();
        sleep_cpu();
        sleep_disable();
    }
}
