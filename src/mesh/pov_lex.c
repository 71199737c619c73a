/* A tokenizer for POV-Ray scene text, just enough for the film maker: words
 * (directives keep their '#': "#local"), unsigned numbers, strings, single
 * punctuation characters; comments (// and nested block comments) skipped.
 * Every token keeps its byte range and line, so the writer can copy the
 * scene byte for byte and replace only chosen numbers. */
#include "pov_internal.h"

#include <ctype.h>
#include <stdlib.h>
#include <string.h>

static bool push(pov_lexer *lx, int kind, size_t start, size_t end, int line)
{
    if (lx->count == lx->cap) {
        size_t cap = lx->cap ? 2 * lx->cap : 1024;
        pov_token *t = realloc(lx->tok, cap * sizeof *t);
        if (!t) return false;
        lx->tok = t;
        lx->cap = cap;
    }
    lx->tok[lx->count++] = (pov_token){kind, start, end, line};
    return true;
}

/* Skip a comment starting at i (text[i] == '/'); false when unterminated. */
static bool skip_comment(const char *s, size_t n, size_t *i, int *line)
{
    if (s[*i + 1] == '/') {
        while (*i < n && s[*i] != '\n') (*i)++;
        return true;
    }
    int depth = 0;
    while (*i + 1 < n) {
        if (s[*i] == '/' && s[*i + 1] == '*') {
            depth++;
            *i += 2;
        } else if (s[*i] == '*' && s[*i + 1] == '/') {
            *i += 2;
            if (--depth == 0) return true;
        } else {
            if (s[*i] == '\n') (*line)++;
            (*i)++;
        }
    }
    return false;
}

static size_t scan_number(const char *s, size_t n, size_t i)
{
    while (i < n && isdigit((unsigned char)s[i])) i++;
    if (i < n && s[i] == '.') i++;
    while (i < n && isdigit((unsigned char)s[i])) i++;
    if (i < n && (s[i] == 'e' || s[i] == 'E')) {
        size_t j = i + 1;
        if (j < n && (s[j] == '+' || s[j] == '-')) j++;
        if (j < n && isdigit((unsigned char)s[j])) {
            i = j;
            while (i < n && isdigit((unsigned char)s[i])) i++;
        }
    }
    return i;
}

spn_status spn__pov_lex(pov_lexer *lx, const char *s, size_t n, const char *name)
{
    memset(lx, 0, sizeof *lx);
    lx->text = s;
    lx->size = n;
    int line = 1;
    size_t i = 0;
    while (i < n) {
        unsigned char c = (unsigned char)s[i];
        size_t start = i;
        int l0 = line;
        bool ok = true;
        if (c == '\n') {
            line++;
            i++;
            continue;
        }
        if (isspace(c)) {
            i++;
            continue;
        }
        if (c == '/' && i + 1 < n && (s[i + 1] == '/' || s[i + 1] == '*')) {
            if (!skip_comment(s, n, &i, &line))
                return spn_error(SPN_ERR_FORMAT, "%s:%d: comment is never closed (missing '*/')", name, l0);
            continue;
        }
        if (isalpha(c) || c == '_' || (c == '#' && i + 1 < n && isalpha((unsigned char)s[i + 1]))) {
            i++;
            while (i < n && (isalnum((unsigned char)s[i]) || s[i] == '_')) i++;
            ok = push(lx, POV_WORD, start, i, l0);
        } else if (isdigit(c) || (c == '.' && i + 1 < n && isdigit((unsigned char)s[i + 1]))) {
            i = scan_number(s, n, i);
            ok = push(lx, POV_NUMBER, start, i, l0);
        } else if (c == '"') {
            i++;
            while (i < n && s[i] != '"' && s[i] != '\n') i += (s[i] == '\\' && i + 1 < n) ? 2 : 1;
            if (i >= n || s[i] != '"') return spn_error(SPN_ERR_FORMAT, "%s:%d: string is never closed", name, l0);
            i++;
            ok = push(lx, POV_STRING, start, i, l0);
        } else {
            i++;
            ok = push(lx, POV_PUNCT, start, i, l0);
        }
        if (!ok) return spn_error(SPN_ERR_NOMEM, "%s: out of memory", name);
    }
    if (!push(lx, POV_END, n, n, line)) return spn_error(SPN_ERR_NOMEM, "%s: out of memory", name);
    return SPN_OK;
}

void spn__pov_lexer_free(pov_lexer *lx)
{
    free(lx->tok);
    memset(lx, 0, sizeof *lx);
}

bool spn__pov_is(const pov_lexer *lx, size_t t, const char *word)
{
    const pov_token *k = &lx->tok[t];
    size_t len = strlen(word);
    return k->end - k->start == len && memcmp(lx->text + k->start, word, len) == 0;
}
