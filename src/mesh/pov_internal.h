/* The POV-Ray scene reader's tokens, shared by pov_lex.c and pov.c. */
#ifndef SPN_POV_INTERNAL_H
#define SPN_POV_INTERNAL_H

#include "mesh_internal.h"

enum { POV_WORD, POV_NUMBER, POV_STRING, POV_PUNCT, POV_END };

typedef struct pov_token {
    int kind;
    size_t start, end; /* byte range in the text */
    int line;
} pov_token;

typedef struct pov_lexer {
    const char *text;
    size_t size;
    pov_token *tok;
    size_t count, cap;
} pov_lexer;

spn_status spn__pov_lex(pov_lexer *lx, const char *text, size_t size, const char *name);
void spn__pov_lexer_free(pov_lexer *lx);
/* Is token t exactly `word` (or the punctuation character as a string)? */
bool spn__pov_is(const pov_lexer *lx, size_t t, const char *word);

#endif
