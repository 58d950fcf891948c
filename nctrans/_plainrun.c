/* nctrans._plainrun — the native kernel for runs of plain ISO blocks.
 *
 * CAM output is tens of thousands of blocks like `N1234 G1 X1.234 Y-5.6 F800.`: address letters and
 * plain numbers, no comment, no expression. In pure Python every such block costs a regex match,
 * a handful of IR objects, a record object and a JSON line (~25 us); this kernel does the same work
 * for a whole run of them straight from the source text (~1 us a block). It is a specialisation of
 * the Python path, never the definition of behaviour:
 *
 *   scan()  accepts a subset of the blocks the ISO front end's plain fast path (fastpath.PLAIN plus
 *           Lowering.hot) accepts: [N] [G0|G1] axis words [F] in that order-free form, ASCII only;
 *   run()   executes such a run exactly as the interpreter's _h_fast would and writes the JSON lines
 *           toolpath_io.to_json_line would write, given the interpreter's state. It stops at the
 *           first block it cannot do identically (unknown axis, no feed, arc mode, a number whose
 *           spelling needs repr(), ...) and hands that block back to Python.
 *
 * tests/test_plainrun.py holds the two to each other on corpus programs and generated ones.
 * Numbers are read with PyOS_string_to_double (what float() uses) and written with glibc's exactly
 * rounded "%.6f", the spelling toolpath_io._spell uses in the same range.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#define MAX_LINE 256   /* longer blocks go to Python */
#define MAX_AXES 9     /* XYZABCUVW */

/* motion modes as the Python side passes them (plainrun.MOTIONS) */
enum { MOTION_RAPID, MOTION_LINEAR, MOTION_CW, MOTION_CCW, MOTION_OTHER };

static const char AXIS_LETTERS[] = "XYZABCUVW";
/* A..Z -> index in AXIS_LETTERS, -1 for a letter that is no axis */
static const signed char AXIS_OF_LETTER[26] = {
    3, 4, 5, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1,      /* A B C D .. M */
    -1, -1, -1, -1, -1, -1, -1, 6, 7, 8, 0, 1, 2,         /* N .. T U V W X Y Z */
};

typedef struct {
    int kind;
    const void *data;
    Py_ssize_t len;
} Text;

typedef struct {
    /* where each word's number starts in the line buffer and how long it is; len 0: absent */
    int axis_at[MAX_AXES], axis_len[MAX_AXES];
    int naxis_words;
    int gmode;      /* -1: no G word, else a MOTION_* code */
    int ijk_at[3], ijk_len[3];          /* centre words I J K; len 0: absent */
    int nijk;
    int feed_at, feed_len;
    int has_number;
} Block;

/* What a character of the text is to read_line: kept, a blank (dropped), a carriage return
 * (kept: only a trailing one is dropped), or one that no plain line holds (a comment character,
 * anything beyond ASCII). */
enum { CH_KEEP, CH_BLANK, CH_CR, CH_STOP };

static int char_class(Py_UCS4 c)
{
    if (c == ' ')
        return CH_BLANK;
    if (c == '\r')
        return CH_CR;
    if (c >= 128 || c == '(' || c == ')' || c == ';')
        return CH_STOP;
    return CH_KEEP;
}

static unsigned char CLASS_OF_BYTE[256];   /* char_class of each Latin-1 character (module init) */

/* A line no plain-run reader takes: LINE_BLANK when it holds only spaces and '\r' (no block: the
 * front end skips it), LINE_OTHER when it cannot be plain (too long, non-ASCII, a comment). */
enum { LINE_BLANK = 0, LINE_OTHER = -1 };

/* Copy text[p:q) without spaces into buf (NUL-terminated) and drop one trailing '\r': the length
 * (> 0), or LINE_BLANK / LINE_OTHER. One pass: the class of each character decides. */
static int read_line(const Text *t, Py_ssize_t p, Py_ssize_t q, char *buf)
{
    int n = 0, only_cr = 1;
    Py_ssize_t i = p;
    if (t->kind == PyUnicode_1BYTE_KIND) {
        /* the usual text (Latin-1 storage): bytes read directly */
        const unsigned char *d = (const unsigned char *)t->data;
        for (; i < q; i++) {
            unsigned char c = d[i];
            int k = CLASS_OF_BYTE[c];
            if (k == CH_BLANK)
                continue;
            if (k == CH_STOP)
                return LINE_OTHER;
            if (n >= MAX_LINE - 1)
                break;
            only_cr &= k == CH_CR;
            buf[n++] = (char)c;
        }
    } else {
        for (; i < q; i++) {
            Py_UCS4 c = PyUnicode_READ(t->kind, t->data, i);
            int k = char_class(c);
            if (k == CH_BLANK)
                continue;
            if (k == CH_STOP)
                return LINE_OTHER;
            if (n >= MAX_LINE - 1)
                break;
            only_cr &= k == CH_CR;
            buf[n++] = (char)c;
        }
    }
    if (i < q) {                       /* too long to be plain: still blank if it is all '\r' */
        for (; i < q; i++) {
            Py_UCS4 c = PyUnicode_READ(t->kind, t->data, i);
            if (c != ' ' && c != '\r')
                return LINE_OTHER;
        }
        return only_cr ? LINE_BLANK : LINE_OTHER;
    }
    if (only_cr)
        return LINE_BLANK;
    if (buf[n - 1] == '\r')
        n--;
    buf[n] = '\0';
    return n;
}

static int is_digit(char c) { return c >= '0' && c <= '9'; }

/* Length of a number [-+]?(\d+\.?\d*|\.\d+) at s, 0 when there is none. */
static int number_len(const char *s)
{
    int i = 0;
    if (s[i] == '-' || s[i] == '+')
        i++;
    if (is_digit(s[i])) {
        while (is_digit(s[i]))
            i++;
        if (s[i] == '.') {
            i++;
            while (is_digit(s[i]))
                i++;
        }
        return i;
    }
    if (s[i] == '.' && is_digit(s[i + 1])) {
        i++;
        while (is_digit(s[i]))
            i++;
        return i;
    }
    return 0;
}

/* The G word as the rules table reads it (normalise_code after lstrip('+')): G0..G3 as their
 * MOTION_* code, -1 for anything else (which the plain path does not take). */
static int motion_g(const char *s, int len)
{
    int i = 0, neg = 0;
    if (s[0] == '+')
        i++;
    else if (s[0] == '-') {
        neg = 1;
        i++;
    }
    long whole = 0;
    int digits = 0;
    for (; i < len && is_digit(s[i]); i++) {
        if (whole > 10)
            return -1;
        whole = whole * 10 + (s[i] - '0');
        digits++;
    }
    if (i < len && s[i] == '.') {
        for (i++; i < len; i++)
            if (s[i] != '0')
                return -1;          /* G1.5 and the like: not a plain motion code */
    }
    if (neg && (whole != 0 || digits == 0))
        return -1;                  /* int("-1") is no G code; int("-") is no number at all */
    return whole <= 3 ? (int)whole : -1;
}

/* Strict scanning (dialects whose words are separated, such as Sinumerik and Fagor: `X1 Y2`,
 * never `X1Y2`): the raw line text[p:q) has no blank between an address letter and its number, no
 * letter right after a number (`G1X10`) and nothing but a letter after a blank (`X1 0`, which
 * these dialects read as a syntax error, would clean to X10), so cleaning it changes no word.
 * 1 when it is so. */
static int words_separated(const Text *t, Py_ssize_t p, Py_ssize_t q)
{
    Py_UCS4 prev = ' ';
    for (Py_ssize_t i = p; i < q; i++) {
        Py_UCS4 c = PyUnicode_READ(t->kind, t->data, i);
        int letter = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z');
        if (c == ' ' && ((prev >= 'A' && prev <= 'Z') || (prev >= 'a' && prev <= 'z')))
            return 0;
        if (letter && ((prev >= '0' && prev <= '9') || prev == '.'))
            return 0;
        if (prev == ' ' && c != ' ' && c != '\r' && !letter)
            return 0;
        prev = c;
    }
    return 1;
}

/* Longest number strict scanning takes: longer ones go to the front end, whose lexer checks their
 * range. */
#define STRICT_NUMBER 15

/* Parse a cleaned line into words: 1 when the block is plain (what Lowering.hot takes), else 0.
 * strict: also G and N numbers are unsigned integers (no point) and no number is longer than
 * STRICT_NUMBER characters (what the Sinumerik front end reads as plain words). */
static int parse_block_as(const char *buf, int n, Block *b, int strict)
{
    memset(b, 0, sizeof *b);
    b->gmode = -1;
    int have_target = 0, have_mode = 0, have_feed = 0, have_center = 0;
    int i = 0;
    if (n == 0 || buf[0] == 'O')
        return 0;
    while (i < n) {
        char letter = buf[i];
        if (letter < 'A' || letter > 'Z')
            return 0;
        int at = i + 1;
        int len = number_len(buf + at);
        if (len == 0)
            return 0;
        if (strict && (len > STRICT_NUMBER || ((letter == 'G' || letter == 'N')
                                               && (memchr(buf + at, '.', (size_t)len) != NULL
                                                   || buf[at] == '-' || buf[at] == '+'))))
            return 0;
        int k = AXIS_OF_LETTER[letter - 'A'];
        if (k >= 0) {
            if (b->axis_len[k] != 0)
                return 0;
            b->axis_at[k] = at;
            b->axis_len[k] = len;
            b->naxis_words++;
            have_target = 1;
        } else if (letter == 'G' && !have_mode) {
            int g = motion_g(buf + at, len);
            if (g < 0)
                return 0;
            b->gmode = g;
            have_mode = 1;
        } else if (letter == 'F' && !have_feed) {
            b->feed_at = at;
            b->feed_len = len;
            have_feed = 1;
        } else if (letter >= 'I' && letter <= 'K') {
            int k = letter - 'I';
            if (b->ijk_len[k] != 0)
                return 0;
            b->ijk_at[k] = at;
            b->ijk_len[k] = len;
            b->nijk++;
            have_center = 1;
        } else if (letter == 'N' && !b->has_number && !have_target && !have_mode && !have_feed
                   && !have_center) {
            b->has_number = 1;
        } else {
            return 0;
        }
        i = at + len;
    }
    return 1;
}

static int parse_block(const char *buf, int n, Block *b) { return parse_block_as(buf, n, b, 0); }

/* Exact powers of ten: every 10^k with k <= 22 is a double without rounding. */
/* limits.MAX_COORDINATE: a coordinate beyond it is out of range (NC108, reported by Python) */
#define MAX_COORDINATE 1e12

static const double POW10[] = {1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11,
                               1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

/* float() of a word's number [-+]?(\d+\.?\d*|\.\d+) (number_len's form, no exponent).
 * The common case takes Clinger's exact fast path: when the digits without the point make an
 * integer m < 2^53 and there are k <= 22 digits after the point, m and 10^k are both exact doubles,
 * so m / 10^k is one correctly rounded IEEE division: the double float() returns. Anything
 * longer goes to PyOS_string_to_double (what float() uses), copied out first: the next letter may
 * be an E, which it would read as an exponent. */
static int number_value(const char *buf, int at, int len, double *out)
{
    const char *s = buf + at;
    int i = 0, neg = 0, frac = 0, point = 0;
    unsigned long long m = 0;
    if (s[0] == '-' || s[0] == '+') {
        neg = s[0] == '-';
        i++;
    }
    for (; i < len; i++) {
        char c = s[i];
        if (c == '.') {
            point = 1;
            continue;
        }
        if (m >= (1ULL << 49))          /* one more digit could pass 2^53: the slow path */
            goto slow;
        m = m * 10 + (unsigned long long)(c - '0');
        frac += point;
    }
    if (frac > 22)
        goto slow;
    double v = (double)m / POW10[frac];
    *out = neg ? -v : v;
    return 0;
slow:;
    char tmp[MAX_LINE + 1];
    memcpy(tmp, s, (size_t)len);
    tmp[len] = '\0';
    *out = PyOS_string_to_double(tmp, NULL, NULL);
    if (*out == -1.0 && PyErr_Occurred())
        return -1;
    return 0;
}

static int get_text(PyObject *str, Text *t)
{
    if (!PyUnicode_Check(str)) {
        PyErr_SetString(PyExc_TypeError, "text must be str");
        return -1;
    }
    if (PyUnicode_READY(str) < 0)
        return -1;
    t->kind = PyUnicode_KIND(str);
    t->data = PyUnicode_DATA(str);
    t->len = PyUnicode_GET_LENGTH(str);
    return 0;
}

static Py_ssize_t line_end(const Text *t, Py_ssize_t p, Py_UCS4 sep)
{
    if (t->kind == PyUnicode_1BYTE_KIND && sep < 256) {
        if (p >= t->len)
            return p;
        const char *d = (const char *)t->data;
        const char *hit = memchr(d + p, (int)sep, (size_t)(t->len - p));
        return hit ? (Py_ssize_t)(hit - d) : t->len;
    }
    while (p < t->len && PyUnicode_READ(t->kind, t->data, p) != sep)
        p++;
    return p;
}

/* Whether a parsed block is one the plain path lowers, given the static modal state before it
 * (Lowering.plain_block): centre words only in arc mode, incremental (G91.1), with no canned
 * cycle pending. Updates
 * the state as the front end would (a motion G word sets the mode and ends the cycle). */
static int plain_in_state(const Block *b, int *motion, int *cycle_off, int arc_abs)
{
    int eff = b->gmode >= 0 ? b->gmode : *motion;
    if (b->nijk && (arc_abs || (eff != MOTION_CW && eff != MOTION_CCW)))
        return 0;
    if (b->nijk && b->gmode < 0 && !*cycle_off)
        return 0;
    if (b->gmode >= 0) {
        *motion = b->gmode;
        *cycle_off = 1;
    }
    return 1;
}

/* scan(text, pos, sep, motion, cycle_off, arc_abs[, strict[, max_chars[, max_blocks]]])
 *   -> (end, lines, blocks, motion)
 * The run of plain lines starting at pos, given the front end's static motion mode (a MOTION_*
 * code), whether no canned cycle is active and whether centres are absolute (G90.1): `end` is where the next line starts (len(text) + 1
 * when the run reaches the end of the text), `lines` how many lines it spans, `blocks` how many of
 * them are blocks (blank lines inside the run are not), `motion` the last G word's mode (-1:
 * none). The run never starts with a blank line. strict: see words_separated and parse_block_as
 * (run() needs no flag: it only reads runs scan() gave). max_chars: the longest line the front end
 * reads (limits.MAX_BLOCK_CHARS, as set): a longer one, blank or not, ends the run, so the front
 * end reports it (NC010) where it would without the kernel. max_blocks: stop after that many blocks
 * (the front end asks whether a run starts here; run() finds where it ends). */
static PyObject *scan(PyObject *self, PyObject *args)
{
    PyObject *str;
    Py_ssize_t pos;
    int sepc, motion, cycle_off, arc_abs, strict = 0;
    Py_ssize_t max_chars = PY_SSIZE_T_MAX, max_blocks = PY_SSIZE_T_MAX;
    if (!PyArg_ParseTuple(args, "UnCipp|pnn", &str, &pos, &sepc, &motion, &cycle_off, &arc_abs, &strict,
                          &max_chars, &max_blocks))
        return NULL;
    Text t;
    if (get_text(str, &t) < 0)
        return NULL;
    /* validated at the boundary: the loops below index the text and tables with these */
    if (pos < 0 || pos > t.len || motion < MOTION_RAPID || motion > MOTION_OTHER) {
        PyErr_SetString(PyExc_ValueError, "scan: pos outside the text or motion not a MOTION_* code");
        return NULL;
    }
    char buf[MAX_LINE + 1];
    Block b;
    Py_ssize_t p = pos, lines = 0, blocks = 0, blanks = 0;
    int last_g = -1;
    while (p >= 0 && p <= t.len && blocks < max_blocks) {
        Py_ssize_t q = line_end(&t, p, (Py_UCS4)sepc);
        if (q - p > max_chars)
            break;                     /* NC010: the front end reports it */
        int n = read_line(&t, p, q, buf);
        if (n == LINE_BLANK) {
            if (blocks == 0)
                break;
            blanks++;                  /* counted only if a block follows */
        } else {
            if (n < 0 || (strict && !words_separated(&t, p, q)) || !parse_block_as(buf, n, &b, strict)
                || !plain_in_state(&b, &motion, &cycle_off, arc_abs))
                break;
            if (b.gmode >= 0)
                last_g = b.gmode;
            blocks++;
            lines += blanks + 1;
            blanks = 0;
        }
        p = q + 1;
        if (blanks == 0)
            pos = p;
    }
    return Py_BuildValue("(nnni)", pos, lines, blocks, last_g);
}

/* Whether a line, read the way scan() reads lines, is plain words in any state: the check is
 * scan()'s in the state that takes the most lines (arc mode, no canned cycle, incremental centres). */
static int plain_in_any_state(const char *buf, int n)
{
    Block b;
    int motion = MOTION_CW, cycle_off = 1;
    return n > 0 && parse_block_as(buf, n, &b, 0) && plain_in_state(&b, &motion, &cycle_off, 0);
}

/* quiet(text, pos, sep, marks) -> where the first line at or after pos starts that may hold a
 * control mark (len(text) when none does). `marks` are the characters every mark begins with
 * (the front end derives them from its pattern, see iso_m.frontend._CONTROL); a line is passed
 * over when it holds none of them in either case and nothing beyond ASCII (whose upper case
 * might be one), or when it is plain words (what scan() steps over). The front end then searches
 * only the lines this stops at: most of a CAM program is never looked at in Python. */
static PyObject *quiet(PyObject *self, PyObject *args)
{
    PyObject *str;
    Py_ssize_t pos;
    int sepc;
    const char *marks;
    if (!PyArg_ParseTuple(args, "UnCs", &str, &pos, &sepc, &marks))
        return NULL;
    Text t;
    if (get_text(str, &t) < 0)
        return NULL;
    if (pos < 0 || pos > t.len) {
        PyErr_SetString(PyExc_ValueError, "quiet: pos outside the text");
        return NULL;
    }
    unsigned char mark[256] = {0};
    for (const unsigned char *m = (const unsigned char *)marks; *m; m++) {
        mark[*m] = 1;
        if (*m >= 'A' && *m <= 'Z')
            mark[*m - 'A' + 'a'] = 1;
        else if (*m >= 'a' && *m <= 'z')
            mark[*m - 'a' + 'A'] = 1;
    }
    for (int c = 128; c < 256; c++)
        mark[c] = 1;
    char buf[MAX_LINE + 1];
    while (pos < t.len) {
        Py_ssize_t q = line_end(&t, pos, (Py_UCS4)sepc);
        int marked = 0;
        if (t.kind == PyUnicode_1BYTE_KIND) {
            const unsigned char *d = (const unsigned char *)t.data;
            for (Py_ssize_t i = pos; i < q && !marked; i++)
                marked = mark[d[i]];
        } else {
            for (Py_ssize_t i = pos; i < q && !marked; i++) {
                Py_UCS4 c = PyUnicode_READ(t.kind, t.data, i);
                marked = c >= 128 || mark[c];
            }
        }
        if (marked && !plain_in_any_state(buf, read_line(&t, pos, q, buf)))
            break;
        pos = q + 1;
    }
    return PyLong_FromSsize_t(pos < t.len ? pos : t.len);
}

/* ------------------------------------------------------------------ output buffer */

/* The JSON text is written straight into an ASCII str (no copy into one at the end): `str` holds
 * `cap` characters, the first `len` written. */
typedef struct {
    PyObject *str;
    char *data;
    size_t len, cap;
    size_t first_cap;           /* the size to start with: enough for the whole run as a rule */
} Buf;

static int buf_grow(Buf *b, size_t extra)
{
    if (b->len + extra <= b->cap)
        return 0;
    size_t cap = b->cap ? b->cap : (b->first_cap > (1 << 12) ? b->first_cap : 1 << 12);
    while (cap < b->len + extra)
        cap *= 2;
    PyObject *s = PyUnicode_New((Py_ssize_t)cap, 127);
    if (s == NULL)
        return -1;
    char *d = (char *)PyUnicode_1BYTE_DATA(s);
    if (b->len)
        memcpy(d, b->data, b->len);
    Py_XDECREF(b->str);
    b->str = s;
    b->data = d;
    b->cap = cap;
    return 0;
}

/* The text written as a str of its length (the buffer is handed over), or None when empty. */
static PyObject *buf_take(Buf *b)
{
    PyObject *s = b->str;
    b->str = NULL;
    if (s == NULL || b->len == 0) {
        Py_XDECREF(s);
        return Py_NewRef(Py_None);
    }
    if (PyUnicode_Resize(&s, (Py_ssize_t)b->len) < 0)
        return NULL;                    /* s was released */
    return s;
}

static inline int buf_put(Buf *b, const char *s, size_t n)
{
    if (buf_grow(b, n) < 0)
        return -1;
    memcpy(b->data + b->len, s, n);
    b->len += n;
    return 0;
}

/* toolpath_io._spell for the values it formats with "%.6f": 1e-4 <= |v| < 1e9, and values that
 * round to zero ("0.0"). Returns the length, or -1 when only repr() would spell v the same way. */
static int spell(double v, char *out)
{
    double a = fabs(v);
    if (!(a < 1e9))
        return -1;                      /* also NaN */
    if (a < 1e-4) {
        if (a < 4.9e-7) {
            memcpy(out, "0.0", 4);
            return 3;
        }
        return -1;
    }
    int n;
    double x = v * 1e6;
    double r = nearbyint(x);
    if (a < 1e5 && fabs(fabs(x - r) - 0.5) > 1e-3) {
        /* x is within 1e-5 of v * 10^6 exactly (|x| < 1e11), so unless that is nearly a tie,
         * rounding x rounds the exact value: the digits "%.6f" would print, without printf */
        long long q = (long long)r;
        char digits[24];
        int neg = q < 0, k = 0;
        unsigned long long u = neg ? (unsigned long long)(-q) : (unsigned long long)q;
        do {
            digits[k++] = (char)('0' + u % 10);
            u /= 10;
        } while (u);
        while (k < 7)
            digits[k++] = '0';           /* at least one digit before the point */
        n = 0;
        if (neg)
            out[n++] = '-';
        while (k > 6)
            out[n++] = digits[--k];
        out[n++] = '.';
        while (k > 0)
            out[n++] = digits[--k];
        out[n] = '\0';
    } else {
        n = snprintf(out, 32, "%.6f", v);
        if (n <= 0 || n >= 32)
            return -1;
    }
    while (out[n - 1] == '0')
        n--;
    if (out[n - 1] == '.')
        out[n++] = '0';
    out[n] = '\0';
    return n;
}

/* '{"X":..,"Y":..}' for the given values; -1 when a value needs repr(). */
static int spell_point(const double *v, int naxes, const char *axes, char *out)
{
    int n = 0;
    out[n++] = '{';
    for (int k = 0; k < naxes; k++) {
        if (k)
            out[n++] = ',';
        out[n++] = '"';
        out[n++] = axes[k];
        out[n++] = '"';
        out[n++] = ':';
        int m = spell(v[k], out + n);
        if (m < 0)
            return -1;
        n += m;
    }
    out[n++] = '}';
    out[n] = '\0';
    return n;
}

/* A count in decimal, as "%zd" writes it (no printf in the loop). */
static int spell_int(Py_ssize_t v, char *out)
{
    char digits[24];
    int k = 0, n = 0;
    size_t u = v < 0 ? (size_t)0 - (size_t)v : (size_t)v;
    if (v < 0)
        out[n++] = '-';
    do {
        digits[k++] = (char)('0' + u % 10);
        u /= 10;
    } while (u);
    while (k > 0)
        out[n++] = digits[--k];
    return n;
}

static int read_doubles(PyObject *seq, double *out, int n, const char *what)
{
    if (!PyList_Check(seq) || PyList_GET_SIZE(seq) != n) {
        PyErr_Format(PyExc_ValueError, "%s: a list of %d floats expected", what, n);
        return -1;
    }
    for (int k = 0; k < n; k++) {
        out[k] = PyFloat_AsDouble(PyList_GET_ITEM(seq, k));
        if (out[k] == -1.0 && PyErr_Occurred())
            return -1;
    }
    return 0;
}

static PyObject *doubles_list(const double *v, int n)
{
    PyObject *l = PyList_New(n);
    if (l == NULL)
        return NULL;
    for (int k = 0; k < n; k++) {
        PyObject *f = PyFloat_FromDouble(v[k]);
        if (f == NULL) {
            Py_DECREF(l);
            return NULL;
        }
        PyList_SET_ITEM(l, k, f);
    }
    return l;
}

/* Python's math.hypot for two finite doubles is correctly rounded where glibc's hypot may be off by
 * an ulp; the kernel only uses it to decide an arc is clearly on the circle (see run), far from
 * any threshold, so the last bit never decides anything. */
static double hyp(double a, double b) { return hypot(a, b); }

/* Append s[0:n] to the output buffer, or jump to fail. */
#define PUT(s, n)                                                                                  \
    do {                                                                                           \
        if (buf_put(&out, (s), (size_t)(n)) < 0)                                                   \
            goto fail;                                                                             \
    } while (0)
#define PUTS(lit) PUT(lit, sizeof(lit) - 1)

/* run(text, pos, end, sep, lineno, axes, prog, tot, mach, scale, incremental, motion, feed,
 *     feed_mode_json, rapid_tail, seq, file_json, max_blocks, write, plane, arc_absolute, inch_tol
 *     [, feed_scale[, scan_state]])
 *   -> (pos, lineno, blocks, chunk, records, prog, mach, motion, feed, feed_seen, last_from,
 *       last_arc, last_g, ended)
 *
 * Runs the plain blocks in text[pos:end) (a run scan() found) from the interpreter's state:
 * axes: the program position's axis letters in order ("XYZ"); prog: that position (program
 * coordinates, mm); tot: the total offset per axis, or None when there is none; mach: the machine
 * position per axis; scale: 25.4 under inch units, else 1; motion: a MOTION_* code; feed: the
 * active feed (mm/min) or None; feed_mode_json: ',"feed_mode":"per_min"' as the record writes it;
 * rapid_tail: the spindle and tool fields every motion record ends with; seq: the last record's
 * number; file_json: the file as a JSON string; plane: "XY", "ZX" or "YZ"; arc_absolute: I J K
 * are absolute (G90.1); center_tol: the arc centre tolerance (arcs.CENTER_TOL_*); feed_scale: what
 * an F word is multiplied by (the feed unit -> mm; `scale` when not given, but Sinumerik G70 reads
 * lengths in inch and feeds in mm: 25.4 and 1). scan_state: None when text[pos:end) is a run
 * scan() gave; else (motion, cycle_off, arc_abs, strict, max_chars), the front end's static state
 * where the run starts as scan() takes it, and the run's end is found while it runs (one pass over
 * the lines instead of scan() then run()): each line is first held to scan()'s checks, and the
 * first one that fails them (or the end of the text) ends the run: `ended` is then 1 and `pos`,
 * `lineno` are where the run ends (after its last block: trailing blank lines are not the run's).
 * Returns where
 * it stopped (the first block it cannot run identically, or `end`), the JSON lines (None unless
 * `write`) and the new state; last_arc is (c1, c2, cw) when the last move was an arc; last_g the
 * MOTION_* code of the last G word in the blocks run (-1: none). */
static PyObject *run(PyObject *self, PyObject *args)
{
    PyObject *str, *axes_obj, *prog_obj, *tot_obj, *mach_obj, *feed_obj;
    Py_ssize_t pos, end, lineno, seq, max_blocks;
    int sepc, incremental, motion, write, arc_absolute;
    double scale, center_tol, feed_scale = NAN;
    const char *fm_json, *tail_json, *file_json, *plane;
    Py_ssize_t fm_len, tail_len, file_len, plane_len;
    PyObject *scan_obj = Py_None;
    if (!PyArg_ParseTuple(args, "UnnCnUOOOdpiOs#s#ns#nps#pd|dO", &str, &pos, &end, &sepc, &lineno,
                          &axes_obj, &prog_obj, &tot_obj, &mach_obj, &scale, &incremental, &motion,
                          &feed_obj, &fm_json, &fm_len, &tail_json, &tail_len, &seq, &file_json,
                          &file_len, &max_blocks, &write, &plane, &plane_len, &arc_absolute,
                          &center_tol, &feed_scale, &scan_obj))
        return NULL;
    if (PyTuple_GET_SIZE(args) < 23)
        feed_scale = scale;
    /* open run (scan_state given): the front end's static state, held as scan() holds it */
    int open = scan_obj != Py_None, s_motion = 0, s_cycle_off = 1, s_arc_abs = 0, s_strict = 0;
    Py_ssize_t s_max_chars = PY_SSIZE_T_MAX;
    if (open && (!PyArg_ParseTuple(scan_obj, "ipppn;run: scan_state is (motion, cycle_off, arc_abs, "
                                   "strict, max_chars)", &s_motion, &s_cycle_off, &s_arc_abs, &s_strict,
                                   &s_max_chars)))
        return NULL;
    Text t;
    if (get_text(str, &t) < 0)
        return NULL;
    /* validated at the boundary: the loop indexes the text, KIND[] and the tables with these */
    if (pos < 0 || end < pos || end > t.len || lineno < 0 || max_blocks < 0
        || motion < MOTION_RAPID || motion > MOTION_OTHER || !(scale > 0.0) || !isfinite(scale)
        || !(feed_scale > 0.0) || !isfinite(feed_scale)
        || s_motion < MOTION_RAPID || s_motion > MOTION_OTHER
        || !(center_tol >= 0.0) || !isfinite(center_tol)) {
        PyErr_SetString(PyExc_ValueError, "run: pos/end outside the text, or lineno, max_blocks, "
                        "motion, scale, feed_scale or center_tol out of range");
        return NULL;
    }
    if (plane_len != 0 && !(strcmp(plane, "XY") == 0 || strcmp(plane, "ZX") == 0
                            || strcmp(plane, "YZ") == 0)) {
        PyErr_SetString(PyExc_ValueError, "run: plane must be XY, ZX, YZ or empty");
        return NULL;
    }
    Py_ssize_t axes_len;
    const char *axes = PyUnicode_AsUTF8AndSize(axes_obj, &axes_len);
    if (axes == NULL)
        return NULL;
    if (axes_len > MAX_AXES) {
        PyErr_SetString(PyExc_ValueError, "too many axes");
        return NULL;
    }
    int naxes = (int)axes_len;
    int slot[MAX_AXES];                 /* letter index in AXIS_LETTERS -> position in axes, -1 */
    int linear[MAX_AXES];
    for (int k = 0; k < MAX_AXES; k++)
        slot[k] = -1;
    for (int k = 0; k < naxes; k++) {
        const char *ax = strchr(AXIS_LETTERS, axes[k]);
        if (ax == NULL || axes[k] == '\0') {
            PyErr_Format(PyExc_ValueError, "axis %c is not an ISO axis letter", axes[k]);
            return NULL;
        }
        slot[ax - AXIS_LETTERS] = k;
        linear[k] = strchr("XYZUVW", axes[k]) != NULL;
    }
    /* the plane's axes (first, second, normal) as positions in `axes`, and which centre word
     * (I J K index) belongs to each of the first two; -1 when the position lacks the axis */
    int pa[3] = {-1, -1, -1}, pc[2] = {-1, -1}, pn = -1;
    if (plane_len == 2) {
        const char *normal = strcmp(plane, "XY") == 0 ? "Z" : strcmp(plane, "ZX") == 0 ? "Y" : "X";
        const char names[3] = {plane[0], plane[1], normal[0]};
        for (int j = 0; j < 3; j++) {
            const char *ax = strchr(AXIS_LETTERS, names[j]);
            pa[j] = ax ? slot[ax - AXIS_LETTERS] : -1;
        }
        pc[0] = plane[0] - 'X';         /* X->I, Y->J, Z->K */
        pc[1] = plane[1] - 'X';
        pn = normal[0] - 'X';           /* the centre word along the normal: the control rejects it */
    }
    int arcs_ok = pa[0] >= 0 && pa[1] >= 0 && pa[2] >= 0 && pc[0] >= 0 && pc[0] < 3 && pc[1] >= 0
                  && pc[1] < 3;
    double prog[MAX_AXES], tot[MAX_AXES], mach[MAX_AXES], from[MAX_AXES];
    /* tot None: no offset at all; the interpreter then copies the position (keeps a -0.0) */
    int has_tot = tot_obj != Py_None;
    if (read_doubles(prog_obj, prog, naxes, "prog") < 0 || read_doubles(mach_obj, mach, naxes, "mach") < 0
        || (has_tot && read_doubles(tot_obj, tot, naxes, "tot") < 0))
        return NULL;
    int has_feed = feed_obj != Py_None;
    double feed = 0.0;
    if (has_feed) {
        feed = PyFloat_AsDouble(feed_obj);
        if (feed == -1.0 && PyErr_Occurred())
            return NULL;
    }
    int feed_seen = 0, moved = 0, last_was_arc = 0, last_cw = 0, last_g = -1;
    double last_c1 = 0.0, last_c2 = 0.0;
    Py_ssize_t blocks = 0, records = 0;
    /* Growing the output by doubling copies it about once more; start it at what the run will
     * most likely write: up to max_blocks records of the longest likely size (the text holds at
     * most one block per 3 characters, `X1\n`). The str is cut to its length at the end. */
    Py_ssize_t likely_blocks = (end - pos) / 3 + 1 < max_blocks ? (end - pos) / 3 + 1 : max_blocks;
    Buf out = {NULL, NULL, 0, 0,
               (size_t)likely_blocks * (size_t)(160 + file_len + fm_len + tail_len + 2 * naxes * 24 + 3 * 24)};
    char line[MAX_LINE + 1];
    /* the last move's end is the next one's start: two buffers that swap roles */
    char point_a[MAX_AXES * 48 + 4], point_b[MAX_AXES * 48 + 4], center_json[3 * 48 + 4];
    char *start_json = point_a, *end_json = point_b;
    char feed_json[40];
    int start_len = -1, feed_len = -1;
    double feed_spelled = 0.0;          /* the feed feed_json spells (valid when feed_len >= 0) */
    Block b;
    /* open run: where the last block run ends (the run's end if no block follows), whether the
     * end was found, and the static state after the block being looked at */
    Py_ssize_t tail_pos = pos, tail_lineno = lineno;
    int ended = 0, next_motion = s_motion, next_cycle_off = s_cycle_off;

    while (pos < end && blocks < max_blocks) {
        Py_ssize_t q = line_end(&t, pos, (Py_UCS4)sepc);
        if (open && q - pos > s_max_chars) {
            ended = 1;                  /* NC010: the front end reports it (as scan()) */
            break;
        }
        int n = read_line(&t, pos, q, line);
        if (n == LINE_BLANK) {
            pos = q + 1;
            lineno++;
            continue;
        }
        if (open) {
            /* scan()'s checks, in the front end's static state */
            next_motion = s_motion;
            next_cycle_off = s_cycle_off;
            if (n < 0 || (s_strict && !words_separated(&t, pos, q)) || !parse_block_as(line, n, &b, s_strict)
                || !plain_in_state(&b, &next_motion, &next_cycle_off, s_arc_abs)) {
                ended = 1;
                break;
            }
        } else if (n < 0 || !parse_block(line, n, &b))
            break;                      /* not a run scan() gave: Python takes over */
        /* Work out the whole block before changing any state, so a block the kernel cannot do
         * identically is left entirely to Python. Order as the interpreter: feed, mode, motion. */
        double new_feed = feed;
        int new_has_feed = has_feed;
        if (b.feed_len) {
            double v;
            if (number_value(line, b.feed_at, b.feed_len, &v) < 0)
                goto fail;
            if (!(v >= 0) || !isfinite(v))
                break;                  /* negative feed: a diagnostic Python reports */
            new_feed = v * feed_scale;
            new_has_feed = 1;
        }
        int new_motion = b.gmode >= 0 ? b.gmode : motion;
        int arc = new_motion == MOTION_CW || new_motion == MOTION_CCW;
        if (b.nijk && !arc)
            break;
        double tgt[MAX_AXES], mend[MAX_AXES], c1 = 0.0, c2 = 0.0, mc[3];
        int bail = 0;
        int moves = b.naxis_words || (arc && b.nijk);
        if (moves) {
            if (new_motion == MOTION_OTHER || (new_motion != MOTION_RAPID && !(new_has_feed && new_feed != 0.0)))
                break;                  /* another mode, or a feed move without feed */
            if (arc && (!b.nijk || !arcs_ok))
                break;                  /* radius format, or an arc without centre: Python */
            if (arc && pn >= 0 && pn < 3 && b.ijk_len[pn] != 0)
                break;                  /* a centre word off the plane: Python reports it (NC210) */
            memcpy(tgt, prog, sizeof prog);
            for (int k = 0; k < MAX_AXES && !bail; k++) {
                if (b.axis_len[k] == 0)
                    continue;
                int s = slot[k];
                if (s < 0) {
                    bail = 1;           /* an axis the position does not have yet */
                    break;
                }
                double v;
                if (number_value(line, b.axis_at[k], b.axis_len[k], &v) < 0)
                    goto fail;
                if (linear[s] && scale != 1.0)
                    v = v * scale;
                if (incremental)
                    v += tgt[s];
                tgt[s] = v;
            }
            if (bail)
                break;
            if (arc) {
                /* _arc with centre words: centre from I J K (scaled, relative to the start unless
                 * G90.1), the end must lie on the circle through the start */
                double s1 = prog[pa[0]], s2 = prog[pa[1]], e1 = tgt[pa[0]], e2 = tgt[pa[1]];
                c1 = s1;
                c2 = s2;
                for (int j = 0; j < 2; j++) {
                    int w = pc[j];
                    if (b.ijk_len[w] == 0)
                        continue;
                    double v;
                    if (number_value(line, b.ijk_at[w], b.ijk_len[w], &v) < 0)
                        goto fail;
                    v *= scale;
                    if (j == 0)
                        c1 = arc_absolute ? v : s1 + v;
                    else
                        c2 = arc_absolute ? v : s2 + v;
                }
                double r1 = hyp(s1 - c1, s2 - c2), r2 = hyp(e1 - c1, e2 - c2);
                double err = fabs(r1 - r2);
                /* well inside arcs.check_center's acceptance (err <= tol, or relative < 0.1 %
                 * and err <= 100 tol): anything near its edges goes to Python */
                if (!(r1 > 1e-9) || !(err < 0.5 * center_tol) || !isfinite(c1) || !isfinite(c2))
                    break;
            }
            for (int k = 0; k < naxes; k++) {
                mend[k] = has_tot ? tgt[k] + tot[k] : tgt[k];
                if (!isfinite(mend[k]) || fabs(mend[k]) > MAX_COORDINATE)
                    bail = 1;
            }
            if (bail)
                break;
            if (arc) {
                double cp[3] = {c1, c2, tgt[pa[2]]};
                for (int j = 0; j < 3; j++)
                    mc[j] = has_tot ? cp[j] + tot[pa[j]] : cp[j];
                if (!(fabs(mc[0]) <= MAX_COORDINATE && fabs(mc[1]) <= MAX_COORDINATE
                      && fabs(mc[2]) <= MAX_COORDINATE))
                    break;          /* out of range: Python reports it (NC108) */
            }
            if (write) {
                int el = spell_point(mend, naxes, axes, end_json);
                if (el < 0)
                    break;
                if (start_len < 0) {
                    start_len = spell_point(mach, naxes, axes, start_json);
                    if (start_len < 0)
                        break;
                }
                int cl = 0;
                if (arc) {
                    const char names[3] = {axes[pa[0]], axes[pa[1]], axes[pa[2]]};
                    cl = spell_point(mc, 3, names, center_json);
                    if (cl < 0)
                        break;
                }
                if (new_motion != MOTION_RAPID && (feed_len < 0 || new_feed != feed_spelled)) {
                    feed_len = spell(new_feed, feed_json);
                    if (feed_len < 0)
                        break;
                    feed_spelled = new_feed;
                }
                static const char *KIND[] = {"\"rapid\"", "\"linear\"", "\"arc\"", "\"arc\""};
                static const int KIND_LEN[] = {7, 8, 5, 5};
                char num[24];
                int nl;
                PUTS("{\"seq\":");
                nl = spell_int(seq + 1, num);
                PUT(num, nl);
                PUTS(",\"file\":");
                PUT(file_json, file_len);
                PUTS(",\"line\":");
                nl = spell_int(lineno, num);
                PUT(num, nl);
                PUTS(",\"kind\":");
                PUT(KIND[new_motion], KIND_LEN[new_motion]);
                PUTS(",\"start\":");
                PUT(start_json, start_len);
                PUTS(",\"end\":");
                PUT(end_json, el);
                if (arc) {
                    PUTS(",\"center\":");
                    PUT(center_json, cl);
                    if (new_motion == MOTION_CW)
                        PUTS(",\"direction\":\"cw\",\"plane\":\"");
                    else
                        PUTS(",\"direction\":\"ccw\",\"plane\":\"");
                    PUT(plane, plane_len);
                    PUTS("\",\"turns\":0");
                }
                if (new_motion != MOTION_RAPID) {
                    PUTS(",\"feed\":");
                    PUT(feed_json, feed_len);
                    PUT(fm_json, fm_len);
                }
                PUT(tail_json, tail_len);
                PUTS("}\n");
                char *was_start = start_json;
                start_json = end_json;
                end_json = was_start;
                start_len = el;
            }
            memcpy(from, prog, sizeof prog);
            memcpy(prog, tgt, sizeof prog);
            memcpy(mach, mend, sizeof mend);
            moved = 1;
            last_was_arc = arc;
            last_c1 = c1;
            last_c2 = c2;
            last_cw = new_motion == MOTION_CW;
            seq++;
            records++;
        }
        if (b.feed_len) {
            feed = new_feed;
            has_feed = 1;
            feed_seen = 1;
        }
        motion = new_motion;
        if (b.gmode >= 0)
            last_g = b.gmode;
        blocks++;
        pos = q + 1;
        lineno++;
        s_motion = next_motion;
        s_cycle_off = next_cycle_off;
        tail_pos = pos;
        tail_lineno = lineno;
    }
    if (open && pos >= end && blocks < max_blocks)
        ended = 1;                      /* the text ends: so does the run */
    if (ended) {
        pos = tail_pos;                 /* blank lines after the last block are not the run's */
        lineno = tail_lineno;
    }
    PyObject *chunk = buf_take(&out);
    if (chunk == NULL)
        return NULL;
    PyObject *prog_l = doubles_list(prog, naxes), *mach_l = doubles_list(mach, naxes);
    PyObject *from_l = moved ? doubles_list(from, naxes) : Py_NewRef(Py_None);
    PyObject *feed_o = has_feed ? PyFloat_FromDouble(feed) : Py_NewRef(Py_None);
    PyObject *arc_o = last_was_arc ? Py_BuildValue("(ddO)", last_c1, last_c2, last_cw ? Py_True : Py_False)
                                   : Py_NewRef(Py_None);
    if (prog_l == NULL || mach_l == NULL || from_l == NULL || feed_o == NULL || arc_o == NULL) {
        Py_XDECREF(prog_l);
        Py_XDECREF(mach_l);
        Py_XDECREF(from_l);
        Py_XDECREF(feed_o);
        Py_XDECREF(arc_o);
        Py_DECREF(chunk);
        return NULL;
    }
    return Py_BuildValue("(nnnNnNNiNiNNii)", pos, lineno, blocks, chunk, records, prog_l, mach_l,
                         motion, feed_o, feed_seen, from_l, arc_o, last_g, ended);
fail:
    Py_XDECREF(out.str);
    return NULL;
}

/* spell(v) -> str | None: the kernel's number spelling, for tests against toolpath_io._spell. */
static PyObject *spell_py(PyObject *self, PyObject *arg)
{
    double v = PyFloat_AsDouble(arg);
    if (v == -1.0 && PyErr_Occurred())
        return NULL;
    char out[40];
    int n = spell(v, out);
    if (n < 0)
        Py_RETURN_NONE;
    return PyUnicode_DecodeASCII(out, n, NULL);
}

/* number(s) -> float: the kernel's reading of one word's number (number_len's form), for tests
 * against float(); ValueError when s is not such a number. */
static PyObject *number_py(PyObject *self, PyObject *arg)
{
    Py_ssize_t len;
    const char *s = PyUnicode_Check(arg) ? PyUnicode_AsUTF8AndSize(arg, &len) : NULL;
    if (s == NULL) {
        if (!PyErr_Occurred())
            PyErr_SetString(PyExc_TypeError, "number: str expected");
        return NULL;
    }
    if (len == 0 || len > MAX_LINE - 1 || number_len(s) != len) {
        PyErr_SetString(PyExc_ValueError, "number: not a plain number");
        return NULL;
    }
    double v;
    if (number_value(s, 0, (int)len, &v) < 0)
        return NULL;
    return PyFloat_FromDouble(v);
}

static PyMethodDef methods[] = {
    {"number", number_py, METH_O, "number(s) -> float: the kernel's reading of a word's number"},
    {"spell", spell_py, METH_O, "spell(v) -> the JSON spelling of v, or None where only repr() spells it"},
    {"scan", scan, METH_VARARGS,
     "scan(text, pos, sep, motion, cycle_off, arc_abs[, strict]) -> (end, lines, blocks, motion)"},
    {"quiet", quiet, METH_VARARGS,
     "quiet(text, pos, sep, marks) -> where the first line that may hold a control mark starts"},
    {"run", run, METH_VARARGS, "run the plain blocks of a scanned run (see the module source)"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "nctrans._plainrun",
    "Native kernel for runs of plain ISO blocks (see nctrans/plainrun.py).", -1, methods,
};

PyMODINIT_FUNC PyInit__plainrun(void)
{
    for (int c = 0; c < 256; c++)
        CLASS_OF_BYTE[c] = (unsigned char)char_class((Py_UCS4)c);
    return PyModule_Create(&module);
}
