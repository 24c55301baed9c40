#!/usr/bin/perl
# Doxygen input filter for the Markdown pages of docs/ (docs/Doxyfile, FILTER_PATTERNS): the
# pages are written for GitHub, whose heading anchors Doxygen 1.9 does not make. Prints the page
# with
#   - each heading below the title labelled as GitHub names its anchor (lower case, punctuation
#     dropped, spaces as hyphens, -1, -2 ... on repeats), prefixed by the page's path so that
#     labels are unique across pages: "## Batch mode" in tools.md gets {#tools_batch-mode};
#   - links to such anchors, on the same page (#batch-mode) or another (tools.md#batch-mode,
#     ../tools.md#batch-mode), pointed at those labels;
#   - pictures of data/ (../data/bunny.png) named by file only, found through IMAGE_PATH.
# The files themselves are not changed. Usage: perl docs/doxygen-md-filter.pl FILE.md
use strict;
use warnings;

my $file = shift @ARGV or die "usage: $0 FILE.md\n";
open(my $in, '<', $file) or die "$file: $!\n";
my @lines = <$in>;
close $in;

# The page's path inside docs/, without .md: "tools", "design/readers".
(my $page = $file) =~ s{\\}{/}g;
$page =~ s{^(?:.*/)?docs/}{};
$page =~ s{\.md$}{};
my $page_dir = $page =~ m{^(.*)/} ? $1 : '';

sub page_key { my ($p) = @_; $p =~ s{[^A-Za-z0-9]}{_}g; return $p; }

sub slug {
  my ($text) = @_;
  $text = lc $text;
  $text =~ s/[^a-z0-9 _-]//g;
  $text =~ s/ /-/g;
  return $text;
}

# A link's target resolved against this page's folder: "../tools.md" from design/ is "tools.md".
sub resolve {
  my ($target) = @_;
  my @parts = $page_dir eq '' ? () : split m{/}, $page_dir;
  for my $part (split m{/}, $target) {
    next if $part eq '.' || $part eq '';
    if ($part eq '..' && @parts && $parts[-1] ne '..') { pop @parts; } else { push @parts, $part; }
  }
  return join '/', @parts;
}

sub rewrite_link {
  my ($target) = @_;
  return $target if $target =~ m{^[a-z]+:}i;  # a URL
  if ($target =~ m{^#(.+)$}) {
    return '#' . page_key($page) . '_' . slug($1);
  }
  if ($target =~ m{^([^#]+)\.md#(.+)$}) {
    return '#' . page_key(resolve($1)) . '_' . slug($2);
  }
  my $resolved = resolve($target);
  return $1 if $resolved =~ m{^\.\./data/([^/]+\.(?:png|jpg|jpeg|gif|svg))$}i;
  return $target;
}

my $fence = '';
my $seen_title = 0;
my %used;
for my $line (@lines) {
  if ($fence ne '') {
    $fence = '' if $line =~ /^\s*\Q$fence\E/;
    print $line;
    next;
  }
  if ($line =~ /^\s*(```|~~~)/) {
    $fence = $1;
    print $line;
    next;
  }
  if ($line =~ /^(#{1,6})\s+(.*?)\s*$/ && $line !~ /\{#[^}]*\}\s*$/) {
    my ($hashes, $title) = ($1, $2);
    if (length($hashes) == 1 && !$seen_title) {
      $seen_title = 1;  # the page's title: Doxygen names the page after the file
    } else {
      my $base = slug($title);
      my $id = $base;
      $id = $base . '-' . $used{$base} if $used{$base};
      $used{$base}++;
      $line = "$hashes $title {#" . page_key($page) . "_$id}\n";
    }
  }
  $line =~ s{\]\(([^()\s]+)\)}{'](' . rewrite_link($1) . ')'}ge;
  print $line;
}
