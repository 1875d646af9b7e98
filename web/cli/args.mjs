// Shared by every command module: argument parsing and the input-error type.
// (Command modules import from here, not from ../cli.mjs, which imports them.)

/** An input error: exit status 2 with this message. */
export class UsageError extends Error {}

/**
 * Splits argv into positionals and --options. `spec` maps option names to
 * 'flag' (no value) or 'value'. Unknown options are input errors.
 */
export function parseArgs(argv, spec) {
  const positional = [];
  const options = {};
  for (let i = 0; i < argv.length; i++) {
    const a = argv[i];
    if (a.startsWith('--')) {
      const [name, inline] = a.slice(2).split(/=(.*)/s, 2);
      if (!(name in spec)) throw new UsageError(`unknown option --${name}`);
      if (spec[name] === 'flag') {
        options[name] = true;
      } else {
        const v = inline ?? argv[++i];
        if (v === undefined) throw new UsageError(`--${name} needs a value`);
        options[name] = v;
      }
    } else {
      positional.push(a);
    }
  }
  return { positional, options };
}
